// An image-wide sampling pattern for the stochastic gathers (docs/VCT.md, "A sampling pattern over the
// image"). A gather adds, modulo 1, `pixel_pattern(px, n)` to random numbers that are the same for the
// whole image (drawn from the seed): each pixel's numbers stay uniform, so its estimate is unbiased on
// its own, while the pixels under the denoise kernel take well spread values (a Kronecker lattice over
// the image), so the error the filter leaves sits at high frequencies where it removes it.

// Per-pixel steps of the pattern's three dimensions: pixel (x, y) adds x * step.x + y * step.y. The
// constants are inverse powers of the plastic number p (p^-1 .. p^-4) and the 3-dimensional R
// sequence's root (1.2207...^-1), whose multiples are far from each other modulo 1 (Roberts 2018: the
// R-sequence dither masks).
const vec2 PATTERN_STEP_0 = vec2(0.7548776662, 0.5698402910);
const vec2 PATTERN_STEP_1 = vec2(0.5698402910, 0.3247179572);
const vec2 PATTERN_STEP_2 = vec2(0.3247179572, 0.8191725134);
// The step of the n-th gather of a progressive refinement: each pixel's samples form a Kronecker
// sequence of their own. Chosen among random steps for two things at once: the first 16 points are
// spread out (nearest pair 0.15 apart in the first two dimensions, R2's 0.17) and no n x step (n < 16)
// comes within 0.02 of the pattern's offset to a pixel within 8 px, so no pixel repeats a neighbour's
// samples (R2's steps are the pattern's own: sample n at x would be sample 0 at x + n).
const vec3 PATTERN_SAMPLE_STEP = vec3(0.758266, 0.824043, 0.956173);

// The pattern's three offsets at pixel px for the gather of index sample_index (0 for an update's).
vec3 pixel_pattern(ivec2 px, int sample_index) {
    vec2 q = vec2(px);
    return fract(vec3(dot(q, PATTERN_STEP_0), dot(q, PATTERN_STEP_1), dot(q, PATTERN_STEP_2))
                 + float(sample_index) * PATTERN_SAMPLE_STEP);
}
