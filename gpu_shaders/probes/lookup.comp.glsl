// Indirect light at every G-buffer texel (camera pixels, lightmap texels, or with a later bounce the
// probes' own atlas) from the 8 probes around it, weighted as probes/weights.glsl says (trilinear x
// back-face x Chebyshev visibility, taken at the point moved normal_bias_m along the normal so a
// receiver on a wall is tested from just in front of it) and renormalised. Each probe's irradiance is
// the windowed clamped-cosine convolution of its L2 SH about n, clamped at 0:
// E = max(0, sum_i c_i h_l A_l Y_i(n)) with the deringing window h_l (common/sh.glsl),
// or with IRRADIANCE its irradiance cube map read at n; the output is E / pi, Cycles' Diffuse Indirect
// (alpha 0).
#include "common/sh.glsl"
#include "probes/probe.glsl"
#include "probes/weights.glsl"

#ifdef IRRADIANCE
// The irradiance encoding: the probe's irradiance cube map (probes/convolve.comp.glsl) at normal n.
vec3 probe_irradiance(ivec3 q, vec3 n) {
    ivec2 i0, i1;
    vec2 f;
    int face = face_bilinear(n, irradiance_texels, i0, i1, f);
    ivec2 o = tile_origin(probe_index(q), face, irradiance_texels);
    vec3 e00 = texelFetch(irradiance, o + i0, 0).rgb;
    vec3 e10 = texelFetch(irradiance, o + ivec2(i1.x, i0.y), 0).rgb;
    vec3 e01 = texelFetch(irradiance, o + ivec2(i0.x, i1.y), 0).rgb;
    vec3 e11 = texelFetch(irradiance, o + i1, 0).rgb;
    return mix(mix(e00, e10, f.x), mix(e01, e11, f.x), f.y);
}
#else
// The SH encoding: the windowed clamped-cosine convolution of the probe's L2 SH about n, clamped at 0.
vec3 probe_irradiance(ivec3 q, vec3 n) {
    vec3 e = vec3(0.0);
    for (int c = 0; c < 9; ++c) {
        e += texelFetch(sh, ivec2(c * probe_dims.x + q.x, probe_row(q)), 0).rgb * sh2_windowed_cosine_lobe(c, n);
    }
    return max(e, vec3(0.0));
}
#endif

void main() {
    ivec2 px = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(px, imageSize(indirect)))) {
        return;
    }
    vec4 pos = texelFetch(gbuf_position, px, 0);
    if (pos.w == 0.0) {
        imageStore(indirect, px, vec4(0.0));
        return;
    }
    vec3 n = normalize(texelFetch(gbuf_normal, px, 0).xyz);
    vec3 p_test = pos.xyz + n * normal_bias_m;
    ivec3 base;
    vec3 frac;
    probe_cell_around(p_test, base, frac);
    vec3 sum = vec3(0.0);
    float total = 0.0;
    for (int k = 0; k < 8; ++k) {
        ivec3 q;
        float weight = probe_weight(k, base, frac, pos.xyz, n, p_test, q);
        if (weight > 0.0) {
            sum += weight * probe_irradiance(q, n);
            total += weight;
        }
    }
    vec3 irradiance = sum / max(total, MIN_TOTAL_WEIGHT);
    imageStore(indirect, px, vec4(irradiance / 3.14159265, 0.0));
}
