// Lambertian emitters from the flux on each side of a cell's plane (diffusion_reference.emit): each side
// reflects (ALBEDO: times the voxels' albedo) its flux as a clamped-cosine lobe about its normal,
// flux / pi x sh_cosine_lobe(+-n) W/sr, whose integral is the flux; an empty cell emits isotropically.
// ATLAS: the fluxes come from the injection atlases (layer z = tile z, passes/atlas.py), else from volumes.
// emitting_class >= 0 (cell.glsl's emitter classes): only the sides of that class emit; an empty cell, which
// has no side, emits 1/5 of its light in each of the six passes, so that every side, which takes in five
// of them, receives all of it.
// CONES (cone_fields.py): one face cone's field: each lobe's part in the cone, projected onto the
// cone's restricted L1 basis (cone_lobe), an empty cell's light times cone_iso.
#include "common/sh.glsl"
#include "diffusion/cell.glsl"
#ifdef ATLAS
#include "common/atlas.glsl"
#endif

#ifdef CONES
const mat4 cone_gram_inv = CONE_GRAM_INV;
const vec4 cone_iso = CONE_ISO;

// Midpoint (i, j) of the EMIT_QUADRATURE^2 grid on cube face f (cone_fields.face_quadrature: the two
// other axes in order), unit, and its solid angle (sr) in dw.
vec3 cone_face_point(int f, int i, int j, out float dw) {
    float step_size = 2.0 / float(EMIT_QUADRATURE);
    float s = (float(i) + 0.5) * step_size - 1.0;
    float t = (float(j) + 0.5) * step_size - 1.0;
    float sign = (f & 1) == 0 ? 1.0 : -1.0;
    int axis = f >> 1;
    vec3 p = axis == 0 ? vec3(sign, s, t) : (axis == 1 ? vec3(s, sign, t) : vec3(s, t, sign));
    float r = length(p);
    dw = step_size * step_size / (r * r * r);
    return p / r;
}

// This cone's field of a Lambertian lobe of 1 W about n (cone_fields.lobe_parts): its part in the cone
// projected onto the cone's basis, over the lobe's flux by the same quadrature, so the six cones' parts
// carry exactly 1 W.
vec4 cone_lobe(vec3 n) {
    vec4 part = vec4(0.0);
    float total = 0.0;
    for (int f = 0; f < 6; ++f) {
        for (int i = 0; i < EMIT_QUADRATURE; ++i) {
            for (int j = 0; j < EMIT_QUADRATURE; ++j) {
                float dw;
                vec3 w = cone_face_point(f, i, j, dw);
                float v = max(dot(n, w), 0.0) * dw;
                total += v;
                if (f == CONE) {
                    part += v * sh_basis(w);
                }
            }
        }
    }
    return total > 0.0 ? cone_gram_inv * part / total : vec4(0.0);
}
#endif

void main() {
    ivec3 c = ivec3(gl_GlobalInvocationID);
    if (any(greaterThanEqual(c, dims))) {
        return;
    }
#ifdef ATLAS
    ivec2 at = atlas_texel(c);
    vec3 fp = texelFetch(flux_plus, at, 0).rgb;
    vec3 fm = texelFetch(flux_minus, at, 0).rgb;
#else
    vec3 fp = texelFetch(flux_plus, c, 0).rgb;
    vec3 fm = texelFetch(flux_minus, c, 0).rgb;
#endif
#ifdef ALBEDO
    vec3 albedo = texelFetch(vox_albedo, c, 0).rgb;
    fp *= albedo;
    fm *= albedo;
#endif
    vec4 r, g, b;
    if (diffusion_occupied(texelFetch(cell_block, c, 0))) {
        vec3 n = texelFetch(cell_normal, c, 0).xyz;
        if (emitting_class != DIFFUSION_EVERY_CLASS) {
            fp *= float(emitter_class(n) == emitting_class);
            fm *= float(emitter_class(-n) == emitting_class);
        }
#ifdef CONES
        vec4 lp = cone_lobe(n);
        vec4 lm = cone_lobe(-n);
#else
        vec4 lp = sh_cosine_lobe(n) * (1.0 / SH_A0);
        vec4 lm = sh_cosine_lobe(-n) * (1.0 / SH_A0);
#endif
        r = fp.r * lp + fm.r * lm;
        g = fp.g * lp + fm.g * lm;
        b = fp.b * lp + fm.b * lm;
    } else {
        float share = emitting_class == DIFFUSION_EVERY_CLASS ? 1.0 : 0.2;
#ifdef CONES
        vec3 light = share * (fp + fm);
        r = light.r * cone_iso;
        g = light.g * cone_iso;
        b = light.b * cone_iso;
#else
        vec3 c0 = share * (fp + fm) / DIFFUSION_FLUX_PER_C0;
        r = vec4(c0.r, 0.0, 0.0, 0.0);
        g = vec4(c0.g, 0.0, 0.0, 0.0);
        b = vec4(c0.b, 0.0, 0.0, 0.0);
#endif
    }
    imageStore(sh_r, c, r);
    imageStore(sh_g, c, g);
    imageStore(sh_b, c, b);
}
