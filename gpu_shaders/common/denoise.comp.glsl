// One iteration of the edge-aware a-trous wavelet filter (passes/denoise.py, whose numpy `reference`
// is this shader's twin): every covered pixel becomes the normalised, G-buffer-weighted mean of the
// 5 x 5 taps `step_px` pixels apart around it. PRODUCTS (1 to 3) images of one view are filtered
// together, source<k> into filtered<k>: a tap's G-buffer weight, most of the work, is computed once for
// all of them, and each comes out as it would alone. Except in the GUIDED iteration the weights never look
// at the values, so those iterations are linear: a flat field stays flat and only geometry stops them.
//
// A tap's weight is the B3-spline kernel times
// - normal agreement max(0, n . n_q)^normal_power (creases),
// - exp(-(plane^2 + excess^2)) with plane = |n . (p_q - p)| / (plane_sigma * footprint) (depth steps)
//   and excess = max(0, |p_q - p| - expected) / (position_sigma * expected), expected = |offset| *
//   footprint (surfaces that are neighbours in the image but apart in space: silhouettes, and the UV
//   charts of a lightmap).
// The footprint (m) is the distance to the nearest covered neighbour along x and along y, the larger of
// the two: the nearest neighbour lies on the pixel's own surface, even next to an edge.
//
// GUIDED (the last iteration, passes/denoise.py): a tap also weighs exp(-|l_q - l| / (luminance_sigma *
// sd)), per product: l the luminance of its source (the geometric iterations' output), sd the noise
// that output keeps: the standard deviation of its unfiltered luminance over the 5 x 5 taps 1 px apart
// (the same G-buffer weights) times raw_noise_factor (denoise.noise_factor of the iterations before).
// Where the values differ by more than the noise explains (a real gradient) the taps stop; within the
// noise the iteration widens the kernel (SVGF's edge-stopping function, Schied et al. 2017, from one
// frame).
//
// FIRST (iteration 0) measures what the later ones reuse and writes it to `guide`: x the footprint
// (-1 for an isolated pixel), 1 + k the k-th product's luminance spread over its taps. Its taps are
// those the guided iteration's spread needs (1 px apart, unfiltered input, the same weights), so that
// costs a few multiplies there instead of a second 5 x 5 loop; every later iteration reads its
// footprint instead of fetching four neighbours again.

#include "common/gbuffer_weight.glsl"

// The k-th product's input and output (k < PRODUCTS; a constant once loops unroll).
vec4 source_at(int k, ivec2 q) {
#if PRODUCTS > 2
    if (k == 2) {
        return texelFetch(source2, q, 0);
    }
#endif
#if PRODUCTS > 1
    if (k == 1) {
        return texelFetch(source1, q, 0);
    }
#endif
    return texelFetch(source0, q, 0);
}

void store(int k, ivec2 px, vec4 value) {
#if PRODUCTS > 2
    if (k == 2) {
        imageStore(filtered2, px, value);
        return;
    }
#endif
#if PRODUCTS > 1
    if (k == 1) {
        imageStore(filtered1, px, value);
        return;
    }
#endif
    imageStore(filtered0, px, value);
}

const vec3 LUMA = vec3(0.2126, 0.7152, 0.0722);

void main() {
    ivec2 px = ivec2(gl_GlobalInvocationID.xy);
    ivec2 size = textureSize(gbuf_position, 0);
    if (any(greaterThanEqual(px, size))) {
        return;
    }
    vec4 pos = texelFetch(gbuf_position, px, 0);
    if (pos.w == 0.0) {
        for (int k = 0; k < PRODUCTS; k++) {
            store(k, px, vec4(0.0));  // no geometry: stays exactly 0
        }
        return;
    }
    vec3 p = pos.xyz;
#ifdef FIRST
    float footprint = max(axis_footprint(px, p, ivec2(1, 0), size), axis_footprint(px, p, ivec2(0, 1), size));
#else
    vec4 measured = texelFetch(guide, px, 0);  // FIRST's: (footprint, each product's luminance spread)
    float footprint = measured.x;
#endif
    if (footprint <= 0.0) {
        for (int k = 0; k < PRODUCTS; k++) {
            store(k, px, source_at(k, px));  // isolated pixel: no scale to compare with
        }
#ifdef FIRST
        imageStore(guide, px, vec4(-1.0, 0.0, 0.0, 0.0));
#endif
        return;
    }
    vec3 n = texelFetch(gbuf_normal, px, 0).xyz;
#ifdef GUIDED
    float luminance[PRODUCTS], scale[PRODUCTS];
    for (int k = 0; k < PRODUCTS; k++) {
        luminance[k] = dot(source_at(k, px).rgb, LUMA);
        // 1e-30: a noiseless neighbourhood stops every tap that differs at all (a flat field still averages).
        scale[k] = luminance_sigma * measured[1 + k] * raw_noise_factor + 1e-30;
    }
#endif
    vec4 sum[PRODUCTS];
    float total[PRODUCTS];
#ifdef FIRST
    float luminance_sum[PRODUCTS], luminance_square_sum[PRODUCTS];  // the spread's moments, weighted
#endif
    for (int k = 0; k < PRODUCTS; k++) {
        sum[k] = vec4(0.0);
        total[k] = 0.0;
#ifdef FIRST
        luminance_sum[k] = 0.0;
        luminance_square_sum[k] = 0.0;
#endif
    }
    for (int j = -2; j <= 2; j++) {
        for (int i = -2; i <= 2; i++) {
            ivec2 offset = ivec2(i, j) * step_px;
            ivec2 q = px + offset;
            if (!covered(q, size)) {
                continue;
            }
            float w = b3(i) * b3(j);
            if (i != 0 || j != 0) {
                w *= geometry_weight(q, offset, p, n, footprint);
            }
            for (int k = 0; k < PRODUCTS; k++) {
                vec4 value = source_at(k, q);
                float wk = w;
#ifdef GUIDED
                if (i != 0 || j != 0) {
                    wk *= exp(-abs(dot(value.rgb, LUMA) - luminance[k]) / scale[k]);
                }
#endif
#ifdef FIRST
                float l = dot(value.rgb, LUMA);
                luminance_sum[k] += w * l;
                luminance_square_sum[k] += w * l * l;
#endif
                sum[k] += wk * value;
                total[k] += wk;
            }
        }
    }
    for (int k = 0; k < PRODUCTS; k++) {
        store(k, px, sum[k] / total[k]);  // total >= the centre's kernel weight > 0
    }
#ifdef FIRST
    vec4 spread = vec4(footprint, 0.0, 0.0, 0.0);
    for (int k = 0; k < PRODUCTS; k++) {
        float mean = luminance_sum[k] / total[k];
        spread[1 + k] = sqrt(max(luminance_square_sum[k] / total[k] - mean * mean, 0.0));
    }
    imageStore(guide, px, spread);
#endif
}
