// Per pixel, how much of the denoise filter's kernel at STEP_PX lies on its own surface
// (passes/surface_support.py): 1 on a flat plane, -1 without a covered neighbour, 1 without geometry.
#include "common/gbuffer_weight.glsl"

void main() {
    ivec2 px = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(px, imageSize(support)))) {
        return;
    }
    vec4 pos = texelFetch(gbuf_position, px, 0);
    float value = 1.0;  // no geometry: nothing to gather, nothing to flag
    if (pos.w != 0.0) {
        value = surface_support(px, pos.xyz, texelFetch(gbuf_normal, px, 0).xyz, STEP_PX);
    }
    imageStore(support, px, vec4(value, 0.0, 0.0, 0.0));
}
