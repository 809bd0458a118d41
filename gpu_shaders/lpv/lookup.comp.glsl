// LPV lookup: trilinear SH (accumulated intensity, W/sr per cell) at the G-buffer position moved half a
// cell along the normal. Intensity over a cell's cross-section h^2 is radiance-like: the irradiance on
// a surface of normal n is E = max(0, c . cosine_lobe(-n)) / h^2 (the grid stores direction of travel,
// so the light arriving at the surface travels along -n). Output: E / pi (Cycles' Diffuse Indirect),
// written, or with ACCUMULATE added to what `indirect` holds.
// GEOMETRY_VOLUME: the 8 trilinear corners are weighted by their transmittance along n as propagation
// saw it, 1 - min(1, area * |n_cell . n|), and renormalised: a cell holding the receiving surface (or
// another surface facing the same way) holds light that entered it through a face its own geometry
// half-blocked, not the light arriving at the surface (docs/LPV.md, "Lookup").
// CASCADE: this grid is a finer cascade; `indirect` holds its parent's answer (coarsest first) and is
// blended towards this one's with weight w = clamp((d - band_start) / band_cells, 0, 1), d the distance
// in cells from the sample point to the nearest interior face (lpv_cascade.blend_weight is the twin).
// The weights of a chain of cascades sum to 1, so no light is counted twice.
// Emitter classes (docs/LPV.md, "Emitter classes"): EMITTER_PASS runs once per class with that class's
// light alone in acc_*, and writes the signed lobe reading (before the clamp and the units) into
// own_light at the pixels whose normal is of class `emitter`; OWN_LIGHT then reads the total and
// subtracts own_light before the clamp, so a surface reads every class but its own. The reading is
// linear in acc, so total - own is the reading of the other classes' sum.
#include "common/sh.glsl"
#ifdef EMITTER_PASS
#include "lpv/emitter_class.glsl"
#endif

vec4 lobe_dot(ivec3 c, vec4 lobe) {
    return vec4(dot(texelFetch(acc_r, c, 0), lobe), dot(texelFetch(acc_g, c, 0), lobe),
                dot(texelFetch(acc_b, c, 0), lobe), 0.0);
}

void main() {
    ivec2 px = ivec2(gl_GlobalInvocationID.xy);
#ifdef EMITTER_PASS
    if (any(greaterThanEqual(px, imageSize(own_light)))) {
#else
    if (any(greaterThanEqual(px, imageSize(indirect)))) {
#endif
        return;
    }
    vec4 pos = texelFetch(gbuf_position, px, 0);
#ifdef EMITTER_PASS
    vec3 n = normalize(texelFetch(gbuf_normal, px, 0).xyz);
    if (pos.w == 0.0 || emitter_class(n) != emitter) {
        return;  // another pass's pixel; background pixels are never read
    }
#else
    if (pos.w == 0.0) {
        imageStore(indirect, px, vec4(0.0));
        return;
    }
    vec3 n = normalize(texelFetch(gbuf_normal, px, 0).xyz);
#endif
    vec3 g = (pos.xyz + (lookup_offset_cells * cell_size) * n - grid_origin) / cell_size;
#ifdef CASCADE
    vec3 d_lo = mix(vec3(1e30), g, bvec3(interior_lo));
    vec3 d_hi = mix(vec3(1e30), vec3(dims) - g, bvec3(interior_hi));
    float d = min(min(min(d_lo.x, d_lo.y), d_lo.z), min(min(d_hi.x, d_hi.y), d_hi.z));
    float w_cascade = clamp((d - band_start) / band_cells, 0.0, 1.0);
    if (w_cascade == 0.0) {
        return;  // the parent's answer stands
    }
#endif
    vec4 lobe = sh_cosine_lobe(-n);
#ifdef GEOMETRY_VOLUME
    vec3 t = g - 0.5;  // cell centres at i + 0.5
    ivec3 i0 = ivec3(floor(t));
    vec3 f = t - vec3(i0);
    vec4 sum_aware = vec4(0.0);
    vec4 sum_plain = vec4(0.0);
    float w_aware = 0.0;
    for (int k = 0; k < 8; ++k) {
        ivec3 corner = ivec3(k & 1, (k >> 1) & 1, k >> 2);
        ivec3 c = clamp(i0 + corner, ivec3(0), dims - 1);  // clamp-to-edge, as the sampler does
        vec3 wv = mix(1.0 - f, f, vec3(corner));
        float w = wv.x * wv.y * wv.z;
        vec4 nv = texelFetch(vox_normal, c, 0);
        float through = 1.0 - min(1.0, nv.w * abs(dot(nv.xyz, n)));
        vec4 v = lobe_dot(c, lobe);
        sum_plain += w * v;
        sum_aware += (w * through) * v;
        w_aware += w * through;
    }
    // Every corner blocked (inside a solid): plain trilinear.
    vec3 s = (w_aware > 1e-4 ? sum_aware / w_aware : sum_plain).rgb;
#else
    vec3 uvw = g / vec3(dims);  // texel centres at (i + 0.5) / dims: linear filtering is trilinear SH
    vec3 s = vec3(dot(texture(acc_r, uvw), lobe), dot(texture(acc_g, uvw), lobe), dot(texture(acc_b, uvw), lobe));
#endif
#ifdef EMITTER_PASS
    imageStore(own_light, px, vec4(s, 1.0));
    return;
#else
#ifdef OWN_LIGHT
    s -= texelFetch(own_light, px, 0).rgb;
#endif
    vec3 e = max(s, vec3(0.0));
    vec3 out_e = e / (cell_size * cell_size * SH_A0);
#ifdef ACCUMULATE
    // One bounce's volume added to the earlier bounces' image: each bounce is clamped on its own, so a
    // later bounce's negative L1 ringing cannot take light away from an earlier one.
    out_e += imageLoad(indirect, px).rgb;
#endif
#ifdef CASCADE
    out_e = mix(imageLoad(indirect, px).rgb, out_e, w_cascade);
#endif
    imageStore(indirect, px, vec4(out_e, 1.0));
#endif
}
