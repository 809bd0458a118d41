// View importance of an RSM face's blocks, step 3 of 3: the probability block_pdf.x that a strata draw
// lands in each block, and whether the gather draws by it at all (block_pdf.y, 1 or 0, the same in
// every block).
//
// q: a block's mean share over the receivers the face lights (step 2's sums over their total; none lit:
// unguided). Guided, a block's probability is q mixed with the uniform 1 / N (N blocks):
// p = (1 - VIEW_SHARE) / N + VIEW_SHARE q. The uniform part keeps every block drawn, so a pixel whose
// light the sparse receivers did not see still gets draws there (its variance grows by at most
// 1 / (1 - VIEW_SHARE)). For a receiver whose light is spread over the blocks as q, drawing by p
// instead of one draw per block scales the variance by
//     R = sum q^2 / p / (N sum q^2).
// Guided drawing walks the blocks' running sum and costs the gather 1.3-1.5x on llvmpipe (a look-up per
// block crossed), so it is used only where R < MAX_VARIANCE_RATIO: where the view's light comes from a
// small part of the map. Measured at 128 px (R of the faces; noise between two seeds, unguided ->
// guided): window-room's sun 0.06, 0.041 -> 0.021; Sponza's sun 0.07 and most of its point light's
// faces 0.12-0.21, 0.137 -> 0.099; cornell's spot 0.64 and cornell-point's faces 0.5-0.9 stay unguided.
// At 0.5 the emissive panel's faces (0.24-0.54) were guided too, for 1.34x its gather and no less noise
// (0.0090 -> 0.0086): the near draws already hold its near field, which R does not know of.

const float VIEW_SHARE = 0.5;
const float MAX_VARIANCE_RATIO = 0.25;

void main() {
    ivec2 ij = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(ij, ivec2(strata_per_side)))) {
        return;
    }
    float blocks = float(strata_per_side * strata_per_side);
    float lit = 0.0;
    for (int j = 0; j < strata_per_side; ++j) {
        for (int i = 0; i < strata_per_side; ++i) {
            lit += texelFetch(block_mean, ivec2(i, j), 0).x;
        }
    }
    float sum_q2 = 0.0;
    float sum_q2_over_p = 0.0;
    for (int j = 0; j < strata_per_side && lit > 0.0; ++j) {
        for (int i = 0; i < strata_per_side; ++i) {
            float q = texelFetch(block_mean, ivec2(i, j), 0).x / lit;
            sum_q2 += q * q;
            sum_q2_over_p += q * q / ((1.0 - VIEW_SHARE) / blocks + VIEW_SHARE * q);
        }
    }
    bool guided = lit > 0.0 && sum_q2_over_p < MAX_VARIANCE_RATIO * blocks * sum_q2;
    float q = lit > 0.0 ? texelFetch(block_mean, ij, 0).x / lit : 0.0;
    float p = guided ? (1.0 - VIEW_SHARE) / blocks + VIEW_SHARE * q : 1.0 / blocks;
    imageStore(block_pdf, ij, vec4(p, guided ? 1.0 : 0.0, 0.0, 0.0));
}
