// Evaluates common/bvh.glsl's bvh_occluded for one ray per texel (origin in `origins`.xyz, s_min in its
// w; direction in `directions`.xyz), so tests can compare it with bvh.occluded: 1 or 0 in hit_out.x.
#include "common/bvh.glsl"

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(p, textureSize(origins, 0)))) {
        return;
    }
    vec4 o = texelFetch(origins, p, 0);
    vec3 w = texelFetch(directions, p, 0).xyz;
    int hint = -1;
    imageStore(hit_out, p, vec4(bvh_occluded(o.xyz, w, o.w, 1e30, hint) ? 1.0 : 0.0, 0.0, 0.0, 0.0));
}
