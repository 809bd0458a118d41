// Indirect light at every G-buffer texel (camera pixels, lightmap texels, or with a later bounce the
// probes' own atlas) from the 8 probes around it (DDGI's weighting of paper 004's interpolation):
//   weight = trilinear x (back-face term ((1 + n.to_probe) / 2)^2 + 0.2) x visibility,
// summed over the probes that are on and renormalised, sum / max(total, MIN_TOTAL_WEIGHT): a receiver
// that sees none of its probes (inside a closed block) fades to 0 instead of taking the mean of probes
// it cannot see. The trilinear weights and the visibility are taken at the point moved normal_bias_m
// along the normal, so a receiver on a wall is tested from just in front of it. Visibility (Chebyshev,
// distance moments m1, m2 towards that point): 1 when r <= m1, else c = (var / (var + (r - m1)^2))^3
// with var = max(m2 - m1^2, min_variance_m2), remapped to (c - VIS_CUTOFF) / (1 - VIS_CUTOFF) and
// clamped at 0, so a wall between the probe and the point gives exactly 0 (continuously). Each probe's
// irradiance is the clamped-cosine convolution of its L2 SH about n, clamped at 0: E = max(0, sum_i
// c_i A_l Y_i(n)), or with IRRADIANCE its irradiance cube map read at n; the output is E / pi, Cycles'
// Diffuse Indirect (alpha 0).
const float VIS_CUTOFF = 1e-3;
const float MIN_TOTAL_WEIGHT = 1e-3;
#include "common/sh.glsl"
#include "probes/probe.glsl"

vec2 probe_moments(int p, vec3 d) {
    ivec2 i0, i1;
    vec2 f;
    int face = face_bilinear(d, face_texels, i0, i1, f);
    ivec2 o = face_origin(p, face);
    vec2 m00 = texelFetch(moments, o + i0, 0).xy;
    vec2 m10 = texelFetch(moments, o + ivec2(i1.x, i0.y), 0).xy;
    vec2 m01 = texelFetch(moments, o + ivec2(i0.x, i1.y), 0).xy;
    vec2 m11 = texelFetch(moments, o + i1, 0).xy;
    return mix(mix(m00, m10, f.x), mix(m01, m11, f.x), f.y);
}

float chebyshev(vec2 m, float r) {
    if (r <= m.x) {
        return 1.0;
    }
    float variance = max(m.y - m.x * m.x, min_variance_m2);
    float d = r - m.x;
    float w = variance / (variance + d * d);
    return max(w * w * w - VIS_CUTOFF, 0.0) / (1.0 - VIS_CUTOFF);
}

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
// The SH encoding: the clamped-cosine convolution of the probe's L2 SH about n, clamped at 0.
vec3 probe_irradiance(ivec3 q, vec3 n) {
    vec3 e = vec3(0.0);
    for (int c = 0; c < 9; ++c) {
        e += texelFetch(sh, ivec2(c * probe_dims.x + q.x, probe_row(q)), 0).rgb * sh2_cosine_lobe(c, n);
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
    vec3 g = (p_test - probe_first) / probe_spacing;
    ivec3 base = clamp(ivec3(floor(g)), ivec3(0), max(probe_dims - 2, ivec3(0)));
    vec3 frac = clamp(g - vec3(base), 0.0, 1.0);
    vec3 sum = vec3(0.0);
    float total = 0.0;
    for (int k = 0; k < 8; ++k) {
        ivec3 corner = ivec3(k & 1, (k >> 1) & 1, (k >> 2) & 1);
        // An axis of one probe: both corners are that probe, their weights sum to its full share.
        ivec3 q = min(base + corner, probe_dims - 1);
        vec3 tri = mix(1.0 - frac, frac, vec3(corner));
        float weight = tri.x * tri.y * tri.z;
        if (weight <= 0.0 || texelFetch(state, ivec2(q.x, probe_row(q)), 0).x == 0.0) {
            continue;
        }
        vec3 probe = probe_position(q);
        vec3 to_probe = probe - pos.xyz;
        float len = length(to_probe);
        float facing = len > 0.0 ? (dot(to_probe / len, n) + 1.0) * 0.5 : 1.0;
        float visible = facing * facing + 0.2;
        if (visibility != 0) {
            vec3 v = p_test - probe;
            float r = length(v);
            visible *= r > 0.0 ? chebyshev(probe_moments(probe_index(q), v / r), r) : 1.0;
        }
        weight *= visible;
        if (weight > 0.0) {
            sum += weight * probe_irradiance(q, n);
            total += weight;
        }
    }
    vec3 irradiance = sum / max(total, MIN_TOTAL_WEIGHT);
    imageStore(indirect, px, vec4(irradiance / 3.14159265, 0.0));
}
