// Lambertian emitters from the flux on each side of a cell's plane (diffusion_reference.emit): each side
// reflects (ALBEDO: times the voxels' albedo) its flux as a clamped-cosine lobe about its normal,
// flux / pi x sh_cosine_lobe(+-n) W/sr, whose integral is the flux; an empty cell emits isotropically.
// ATLAS: the fluxes come from the injection atlases (layer z = tile z, passes/atlas.py), else from volumes.
// emitting_class >= 0 (cell.glsl's emitter classes): only the sides of that class emit; an empty cell, which
// has no side, emits 1/5 of its light in each of the six passes, so that every side, which takes in five
// of them, receives all of it.
#include "common/sh.glsl"
#include "diffusion/cell.glsl"
#ifdef ATLAS
#include "common/atlas.glsl"
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
        vec4 lp = sh_cosine_lobe(n) * (1.0 / SH_A0);
        vec4 lm = sh_cosine_lobe(-n) * (1.0 / SH_A0);
        r = fp.r * lp + fm.r * lm;
        g = fp.g * lp + fm.g * lm;
        b = fp.b * lp + fm.b * lm;
    } else {
        float share = emitting_class == DIFFUSION_EVERY_CLASS ? 1.0 : 0.2;
        vec3 c0 = share * (fp + fm) / DIFFUSION_FLUX_PER_C0;
        r = vec4(c0.r, 0.0, 0.0, 0.0);
        g = vec4(c0.g, 0.0, 0.0, 0.0);
        b = vec4(c0.b, 0.0, 0.0, 0.0);
    }
    imageStore(sh_r, c, r);
    imageStore(sh_g, c, g);
    imageStore(sh_b, c, b);
}
