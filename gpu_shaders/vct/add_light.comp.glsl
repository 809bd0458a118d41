// One light's injected VPLs -> flux added to the flux atlas, capped by what the voxelized geometry can
// show. Per cell and travel direction t the scratch atlas holds the light's VPL flux F = sum phi
// max(0, n.t) (W) and lit cross-section S = sum A max(0, n.t) / h^2 (its surfels' areas: RSM footprints,
// in cell cross-sections). Added: F x min(1, MAX_OVERHANG x P_t / S), P_t the voxelizer's projected area
// along t. A VPL's footprint can be far larger than the sliver of surface its cell holds (a grazing
// surfel, a thin object): its whole flux in that cell made level0's radiance c_t / a_t = F / (pi h^2
// P_t) hundreds of times the surface's own (single pixels read 700x Cycles on the conference room at
// 128 cells). The cap scales such cells down to MAX_OVERHANG x the radiance F / (pi h^2 S) of what the
// light lit there. Not 1: footprints alias against cells, S / P_t of fully lit flat walls scatters
// around 1, and a cap of 1 (or 2) darkened Cornell at 128 cells (bias 0.83); spreading F / S over all
// of P_t lit the cells' shadowed geometry too (Sponza 1.29x). Per light, not per view: the faces of a
// point light meeting at a cell share it; S does not depend on power and lights add, so the atlas stays
// linear in each light's power and in the lights. Never adds energy. Measurements: docs/VCT.md.
const float MAX_OVERHANG = 4.0;

#include "common/atlas.glsl"

vec4 capped_flux(vec4 scratch, float projected) {
    return scratch.a > 0.0 ? vec4(scratch.rgb * min(1.0, MAX_OVERHANG * projected / scratch.a), 0.0) : vec4(0.0);
}

void main() {
    ivec3 c = ivec3(gl_GlobalInvocationID);
    if (any(greaterThanEqual(c, dims))) {
        return;
    }
    ivec2 at = atlas_texel(c);
    vec3 p = texelFetch(vox_projected, c, 0).xyz;
    imageStore(flux_px, at, imageLoad(flux_px, at) + capped_flux(texelFetch(light_px, at, 0), p.x));
    imageStore(flux_nx, at, imageLoad(flux_nx, at) + capped_flux(texelFetch(light_nx, at, 0), p.x));
    imageStore(flux_py, at, imageLoad(flux_py, at) + capped_flux(texelFetch(light_py, at, 0), p.y));
    imageStore(flux_ny, at, imageLoad(flux_ny, at) + capped_flux(texelFetch(light_ny, at, 0), p.y));
    imageStore(flux_pz, at, imageLoad(flux_pz, at) + capped_flux(texelFetch(light_pz, at, 0), p.z));
    imageStore(flux_nz, at, imageLoad(flux_nz, at) + capped_flux(texelFetch(light_nz, at, 0), p.z));
}
