// LPV octree, merge one level: the finer level's accumulation (acc_*, read-write) becomes
// w * itself + (1 - w) * the merged coarser level read at its centre (upsample.glsl: trilinear x 1/4).
// w = clamp(rho / epsilon - 1, 0, 1), rho = the finer level's light over the coarser answer's (light =
// c0 summed over the colours, one weight for all three so the blend shifts no hue): the finer level
// counts where its light reaches epsilon times the coarser answer, fully from twice that, and alone
// where the coarser answer holds none. epsilon -> 0 is the paper's rule, the finest level holding light
// (lpv_octree_reference.py derives the rule; mix() keeps each coefficient between the two: no light is
// created).
#include "lpv/upsample.glsl"

void main() {
    ivec3 c = ivec3(gl_GlobalInvocationID);
    if (any(greaterThanEqual(c, dims))) {
        return;
    }
    vec4 fine_r = imageLoad(acc_r, c);
    vec4 fine_g = imageLoad(acc_g, c);
    vec4 fine_b = imageLoad(acc_b, c);
    vec4 up_r = upsampled(coarse_r, c);
    vec4 up_g = upsampled(coarse_g, c);
    vec4 up_b = upsampled(coarse_b, c);
    float fine_light = fine_r.x + fine_g.x + fine_b.x;
    float coarse_light = up_r.x + up_g.x + up_b.x;
    float w = coarse_light > 0.0 ? clamp(fine_light / (epsilon * coarse_light) - 1.0, 0.0, 1.0)
                                 : (fine_light > 0.0 ? 1.0 : 0.0);
    imageStore(acc_r, c, mix(up_r, fine_r, w));
    imageStore(acc_g, c, mix(up_g, fine_g, w));
    imageStore(acc_b, c, mix(up_b, fine_b, w));
}
