// LPV far field, combine: a fine grid's accumulation += the light its far-field grid (twice the cell
// size, same origin, ceil(dims / 2) cells) carried beyond the fine grid's near steps, read at the fine
// cell's centre (upsample.glsl: trilinear times 1/4). Plain trilinear: weighting the corners by their
// geometry (as the lookup does) was measured and was worse (docs/LPV.md, "Far field").
#include "lpv/upsample.glsl"

void main() {
    ivec3 c = ivec3(gl_GlobalInvocationID);
    if (any(greaterThanEqual(c, dims))) {
        return;
    }
    imageStore(acc_r, c, imageLoad(acc_r, c) + upsampled(far_r, c));
    imageStore(acc_g, c, imageLoad(acc_g, c) + upsampled(far_g, c));
    imageStore(acc_b, c, imageLoad(acc_b, c) + upsampled(far_b, c));
}
