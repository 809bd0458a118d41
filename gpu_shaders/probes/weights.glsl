// Which probes a receiver reads and how much (DDGI's weighting of paper 004's interpolation), shared
// by the probes' lookup (probes/lookup.comp.glsl) and the final gather (gather/form_factor.comp.glsl):
//   weight = trilinear x (back-face term ((1 + n.to_probe) / 2)^2 + 0.2) x visibility
// over the 8 probes of the grid cell around the test point p_test = pos + normal_bias_m n (clamped to
// the grid: outside it the outermost probes carry the light); probes that are off weigh 0. Visibility
// (Chebyshev, distance moments m1, m2 towards p_test): 1 when r <= m1, else c = (var / (var + (r -
// m1)^2))^3 with var = max(m2 - m1^2, min_variance_m2), remapped to (c - VIS_CUTOFF) / (1 - VIS_CUTOFF)
// and clamped at 0, so a wall between the probe and the point gives exactly 0 (continuously). Callers
// renormalise by max(total, MIN_TOTAL_WEIGHT): a receiver that sees none of its probes (inside a
// closed block) fades to 0 instead of taking the mean of probes it cannot see.
// Needs probes/probe.glsl, samplers moments and state, uniforms normal_bias_m, min_variance_m2, visibility.
const float VIS_CUTOFF = 1e-3;
const float MIN_TOTAL_WEIGHT = 1e-3;

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

// The grid cell around the test point p_test: its probe (0, 0, 0) corner `base` and the trilinear
// fractions `frac` of p_test in it.
void probe_cell_around(vec3 p_test, out ivec3 base, out vec3 frac) {
    vec3 g = (p_test - probe_first) / probe_spacing;
    base = clamp(ivec3(floor(g)), ivec3(0), max(probe_dims - 2, ivec3(0)));
    frac = clamp(g - vec3(base), 0.0, 1.0);
}

// The weight of corner k (0..7) of that cell for the receiver at pos (normal n), and its probe q.
float probe_weight(int k, ivec3 base, vec3 frac, vec3 pos, vec3 n, vec3 p_test, out ivec3 q) {
    ivec3 corner = ivec3(k & 1, (k >> 1) & 1, (k >> 2) & 1);
    // An axis of one probe: both corners are that probe, their weights sum to its full share.
    q = min(base + corner, probe_dims - 1);
    vec3 tri = mix(1.0 - frac, frac, vec3(corner));
    float weight = tri.x * tri.y * tri.z;
    if (weight <= 0.0 || texelFetch(state, ivec2(q.x, probe_row(q)), 0).x == 0.0) {
        return 0.0;
    }
    vec3 probe = probe_position(q);
    vec3 to_probe = probe - pos;
    float len = length(to_probe);
    float facing = len > 0.0 ? (dot(to_probe / len, n) + 1.0) * 0.5 : 1.0;
    float visible = facing * facing + 0.2;
    if (visibility != 0) {
        vec3 v = p_test - probe;
        float r = length(v);
        visible *= r > 0.0 ? chebyshev(probe_moments(probe_index(q), v / r), r) : 1.0;
    }
    return weight * visible;
}
