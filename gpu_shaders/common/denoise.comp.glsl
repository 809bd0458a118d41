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
// that output keeps: the standard deviation of its unfiltered `raw` luminance over the 5 x 5 taps 1 px
// apart (the same G-buffer weights) times raw_noise_factor (denoise.noise_factor of the iterations
// before). Where the
// values differ by more than the noise explains (a real gradient) the taps stop; within the noise the
// iteration widens the kernel (SVGF's edge-stopping function, Schied et al. 2017, from one frame).

#include "common/gbuffer_weight.glsl"

// The k-th product's input, unfiltered input and output (k < PRODUCTS; a constant once loops unroll).
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

#ifdef GUIDED
const vec3 LUMA = vec3(0.2126, 0.7152, 0.0722);

float raw_luminance(int k, ivec2 q) {
#if PRODUCTS > 2
    if (k == 2) {
        return dot(texelFetch(raw2, q, 0).rgb, LUMA);
    }
#endif
#if PRODUCTS > 1
    if (k == 1) {
        return dot(texelFetch(raw1, q, 0).rgb, LUMA);
    }
#endif
    return dot(texelFetch(raw0, q, 0).rgb, LUMA);
}
#endif

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
    float footprint = max(axis_footprint(px, p, ivec2(1, 0), size), axis_footprint(px, p, ivec2(0, 1), size));
    if (footprint <= 0.0) {
        for (int k = 0; k < PRODUCTS; k++) {
            store(k, px, source_at(k, px));  // isolated pixel: no scale to compare with
        }
        return;
    }
    vec3 n = texelFetch(gbuf_normal, px, 0).xyz;
#ifdef GUIDED
    // Per product: the standard deviation of the raw luminance over the 5 x 5 taps 1 px apart, with the
    // filter's weights, scaled to the noise the geometric iterations left (raw_noise_factor).
    float m1[PRODUCTS], m2[PRODUCTS];
    for (int k = 0; k < PRODUCTS; k++) {
        m1[k] = 0.0;
        m2[k] = 0.0;
    }
    float raw_total = 0.0;
    for (int j = -2; j <= 2; j++) {
        for (int i = -2; i <= 2; i++) {
            ivec2 q = px + ivec2(i, j);
            if (!covered(q, size)) {
                continue;
            }
            float w = b3(i) * b3(j);
            if (i != 0 || j != 0) {
                w *= geometry_weight(q, ivec2(i, j), p, n, footprint);
            }
            for (int k = 0; k < PRODUCTS; k++) {
                float l = raw_luminance(k, q);
                m1[k] += w * l;
                m2[k] += w * l * l;
            }
            raw_total += w;
        }
    }
    float luminance[PRODUCTS], scale[PRODUCTS];
    for (int k = 0; k < PRODUCTS; k++) {
        float mean = m1[k] / raw_total;
        float deviation = sqrt(max(m2[k] / raw_total - mean * mean, 0.0));
        luminance[k] = dot(source_at(k, px).rgb, LUMA);
        // 1e-30: a noiseless neighbourhood stops every tap that differs at all (a flat field still averages).
        scale[k] = luminance_sigma * deviation * raw_noise_factor + 1e-30;
    }
#endif
    vec4 sum[PRODUCTS];
    float total[PRODUCTS];
    for (int k = 0; k < PRODUCTS; k++) {
        sum[k] = vec4(0.0);
        total[k] = 0.0;
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
                sum[k] += wk * value;
                total[k] += wk;
            }
        }
    }
    for (int k = 0; k < PRODUCTS; k++) {
        store(k, px, sum[k] / total[k]);  // total >= the centre's kernel weight > 0
    }
}
