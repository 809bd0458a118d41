// LPV injection: one point per RSM texel (a VPL). The VPL of flux phi (W, per colour) and normal n is a
// Lambertian emitter: radiant intensity I(w) = phi / pi * max(0, n.w) W/sr, whose L1 projection is
// phi / pi * sh_cosine_lobe(n) (integral over the sphere = 2 sqrt(pi) c0 = phi). It is moved 0.6
// cells along n, into the cell in front of its surface, and added to the texel of the cell containing
// it in the injection atlas (lpv_inject.py: z-layer z is tile (z % tiles_x, z / tiles_x)). Empty texels
// and points outside the grid are clipped. Not half a cell: Grid.fit centres the bounds' walls in their
// cells, so half a cell put their VPLs exactly on a border where fp32 rounding picked the cell, and the
// image changed by 45 % with the scene's scale.
// EMITTER_CLASSES: the atlas holds the grid six times over, one block per emitter class (the normal's
// dominant signed axis, lpv/emitter_class.glsl); the VPL goes into its class's block.
#include "common/atlas.glsl"
#include "common/sh.glsl"
#ifdef EMITTER_CLASSES
#include "lpv/emitter_class.glsl"
#endif

void main() {
    ivec2 t = ivec2(texel);
    vec4 pos = texelFetch(rsm_position, t, 0);
    vec3 n = texelFetch(rsm_normal, t, 0).xyz;
    vec3 phi = texelFetch(rsm_flux, t, 0).rgb;
    vec3 g = (pos.xyz + (0.6 * cell_size) * n - grid_origin) / cell_size;
#ifdef EMITTER_CLASSES
    int layer0 = emitter_class(n) * dims.z;
#else
    int layer0 = 0;
#endif
    gl_Position = atlas_splat_position_at(ivec3(floor(g)), layer0, pos.w != 0.0, atlas_size);
    vec4 lobe = sh_cosine_lobe(n) * (1.0 / SH_A0);
    v_r = phi.r * lobe;
    v_g = phi.g * lobe;
    v_b = phi.b * lobe;
}
