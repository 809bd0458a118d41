// The final gather of method `gather` (paper 001; docs/GATHER.md) at every G-buffer texel x (camera
// pixels or lightmap texels) with normal n: for each probe around x (probes/weights.glsl, the weights
// of the probes' lookup) each of its quad lights (gather/quads.comp.glsl) is rebuilt in world space,
// corner c at probe + d_c w_c (w_c the corner's unit direction, d_c its measured distance: the
// distance correction), or where a quad is not whole each of its texels as the piece of its own plane
// its corner directions cut (plane_corner), and adds L F, F its form factor at x:
//   polygon (the default): Lambert's formula for the quad clipped to x's horizon (n . v >= 0),
//     F = 1 / (2 pi) sum over edges (v_i, v_i+1) of angle_i n . (v_i x v_i+1) / |v_i x v_i+1|,
//     angle_i = atan2(|v_i x v_i+1|, v_i . v_i+1), edges whose cross product vanishes skipped;
//     at most 1 however near x lies to the quad;
//   point (POINT_FORM_FACTOR, the paper's baseline): A cos_q cos_x / (pi r^2) to the quad's centre,
//     unbounded as r -> 0.
// A quad seen from behind (x beyond its plane, away from the probe) gives F <= 0 and is clamped to 0.
// L F summed is E / pi of that probe's light, Cycles' Diffuse Indirect. The probes are blended as the
// lookup blends them: sum_p w_p I_p / max(sum_p w_p, MIN_TOTAL_WEIGHT).
// llvmpipe caps an invocation's loops (FACTS.md), so the (probe, face) pairs are split over
// dispatches, items [item_begin, item_end) of the 8 x 6: `indirect` holds (sum, total weight) between
// them (item_begin 0 starts it) and the dispatch whose item_end is 48 writes the blend (alpha 0).
#include "probes/probe.glsl"
#include "probes/weights.glsl"
#include "gather/quad.glsl"

const float PI = 3.14159265;
const int ITEMS = 48;  // 8 probes x 6 faces

#ifdef POINT_FORM_FACTOR
// The point-to-point form factor of the quad (corners v relative to x) at x, its centre as a point
// light of the quad's area: the paper's baseline. r^2 is floored at 1e-12 m^2 only so that a receiver
// on a quad's centre stays finite.
float form_factor(vec3 v0, vec3 v1, vec3 v2, vec3 v3, vec3 n) {
    vec3 centre = 0.25 * (v0 + v1 + v2 + v3);
    // Half the cross product of the diagonals: the quad's area vector, pointing away from the probe
    // (corners counter-clockwise about the probe's view), so the side facing x is -area.
    vec3 area = 0.5 * cross(v2 - v0, v3 - v1);
    float r2 = max(dot(centre, centre), 1e-12);
    return max(dot(area, centre), 0.0) * max(dot(n, centre), 0.0) / (PI * r2 * r2);
}
#else
// Lambert's polygon-to-point form factor of the quad (corners v relative to x, counter-clockwise
// about the direction from x to the quad when x faces its lit side) clipped to x's horizon n . v >= 0.
float form_factor(vec3 v0, vec3 v1, vec3 v2, vec3 v3, vec3 n) {
    vec3 quad[4] = vec3[4](v0, v1, v2, v3);
    vec3 v[5];
    int count = 0;
    for (int i = 0; i < 4; ++i) {
        vec3 a = quad[i];
        vec3 b = quad[(i + 1) % 4];
        float da = dot(n, a);
        float db = dot(n, b);
        // At most 5 corners exactly; one more from fp32 rounding is dropped, not written past v.
        if (da >= 0.0 && count < 5) {
            v[count++] = a;
        }
        if ((da >= 0.0) != (db >= 0.0) && count < 5) {
            v[count++] = mix(a, b, da / (da - db));
        }
    }
    float f = 0.0;
    for (int i = 0; i < count; ++i) {
        vec3 a = v[i];
        vec3 b = v[i + 1 < count ? i + 1 : 0];
        vec3 c = cross(a, b);
        float s = length(c);
        // A vanishing cross product (an edge of no length, or one whose line passes through x) has no
        // plane: its angle is 0, or x lies on the quad's own plane, where the quad gives nothing.
        if (s <= 1e-6 * length(a) * length(b)) {
            continue;
        }
        f += atan(s, dot(a, b)) * dot(n, c) / s;
    }
    return max(f, 0.0) / (2.0 * PI);
}
#endif

// A quad with corners v (relative to x, in corner_offset order) of radiance `light`, at x.
vec3 quad_light(vec3 v0, vec3 v1, vec3 v2, vec3 v3, vec3 light, vec3 n) {
    return light * form_factor(v0, v1, v2, v3, n);
}

// The direction of corner k of a face of face_texels texels a side (unit).
vec3 corner_dir(int face, ivec2 k) {
    return normalize(corner_point(face, k, face_texels));
}

// The light of one face of probe p (its quads, or the texels of a quad that is not whole) at x.
vec3 face_light(int p, int face, vec3 probe_rel, vec3 n) {
    int m = face_quads;
    int k = face_texels / m;
    ivec2 quad_origin = tile_origin(p, face, m);
    ivec2 texel_origin = face_origin(p, face);
    vec3 e = vec3(0.0);
    for (int qy = 0; qy < m; ++qy) {
        for (int qx = 0; qx < m; ++qx) {
            vec4 quad = texelFetch(quad_radiance, quad_origin + ivec2(qx, qy), 0);
            if (quad.w == 0.0) {
                continue;
            }
            ivec2 first = ivec2(qx, qy) * k;
            if (quad.w == 1.0) {
                vec4 d = texelFetch(quad_corners, quad_origin + ivec2(qx, qy), 0);
                e += quad_light(probe_rel + d.x * corner_dir(face, first), probe_rel + d.y * corner_dir(face, first + ivec2(k, 0)),
                                probe_rel + d.z * corner_dir(face, first + ivec2(k, k)),
                                probe_rel + d.w * corner_dir(face, first + ivec2(0, k)), quad.rgb, n);
                continue;
            }
            for (int j = 0; j < k; ++j) {
                for (int i = 0; i < k; ++i) {
                    ivec2 ij = first + ivec2(i, j);
                    vec4 texel = texelFetch(fine_radiance, texel_origin + ij, 0);
                    if (texel.w == 0.0 || all(equal(texel.rgb, vec3(0.0)))) {
                        continue;
                    }
                    vec4 plane = texelFetch(fine_plane, texel_origin + ij, 0);
                    vec3 centre = face_direction(face, texel_st(ij));
                    bool clipped;
                    e += quad_light(probe_rel + plane_corner(plane, centre, corner_dir(face, ij), clipped),
                                    probe_rel + plane_corner(plane, centre, corner_dir(face, ij + ivec2(1, 0)), clipped),
                                    probe_rel + plane_corner(plane, centre, corner_dir(face, ij + ivec2(1, 1)), clipped),
                                    probe_rel + plane_corner(plane, centre, corner_dir(face, ij + ivec2(0, 1)), clipped),
                                    texel.rgb, n);
                }
            }
        }
    }
    return e;
}

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
    vec4 acc = item_begin == 0 ? vec4(0.0) : imageLoad(indirect, px);
    for (int item = item_begin; item < item_end; ++item) {
        int k = item / 6;
        int face = item % 6;
        ivec3 q;
        float weight = probe_weight(k, base, frac, pos.xyz, n, p_test, q);
        if (weight <= 0.0) {
            continue;
        }
        acc.rgb += weight * face_light(probe_index(q), face, probe_position(q) - pos.xyz, n);
        if (face == 0) {
            acc.a += weight;
        }
    }
    if (item_end == ITEMS) {
        acc = vec4(acc.rgb / max(acc.a, MIN_TOTAL_WEIGHT), 0.0);
    }
    imageStore(indirect, px, acc);
}
