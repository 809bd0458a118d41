// View importance of an RSM face's blocks, step 2 of 3: per block, the sum over the receivers of the
// share of their light it holds (rsm/importance.comp.glsl): block_mean, which sums to the number of
// receivers the face lights (step 3 normalises it).

void main() {
    ivec2 ij = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(ij, ivec2(strata_per_side)))) {
        return;
    }
    int b = ij.y * strata_per_side + ij.x;
    float share = 0.0;
    for (int r = 0; r < receivers_per_side * receivers_per_side; ++r) {
        share += texelFetch(block_share, ivec2(b, r), 0).x;
    }
    imageStore(block_mean, ij, vec4(share));
}
