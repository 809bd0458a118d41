// VCT gather at the camera's pixels: indirect = E / pi (Cycles' Diffuse Indirect units) from the
// diffuse cones about the G-buffer normal; ambient occlusion (the cosine-weighted opacity) in `ao`.
#include "vct/cone.glsl"

void main() {
    ivec2 px = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(px, imageSize(indirect)))) {
        return;
    }
    vec4 pos = texelFetch(gbuf_position, px, 0);
    if (pos.w == 0.0) {
        imageStore(indirect, px, vec4(0.0));
        imageStore(ao, px, vec4(0.0));
        return;
    }
    vec3 n = normalize(texelFetch(gbuf_normal, px, 0).xyz);
    uint s = uint(seed) * 2u;
    vec4 e = gather_diffuse(pos.xyz, n, 6.28318531 * random01(uint(px.x), uint(px.y), s),
                            random01(uint(px.x), uint(px.y), s + 1u));
    imageStore(indirect, px, vec4(e.rgb, 1.0));
    imageStore(ao, px, vec4(vec3(1.0 - e.a), 1.0));
}
