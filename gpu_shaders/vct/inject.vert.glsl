// VCT injection: one point per RSM texel (a VPL of reflected flux phi, W, normal n, surfel area A)
// splatted into its cell's texel of a light's scratch atlas (common/atlas.glsl). Six outputs, one per
// axis direction t of travel (+x, -x, +y, -y, +z, -z): (phi, A / h^2) * max(0, n.t), the part of the
// Lambertian VPL's light leaving along t (its projection on the axis lobes) and the cross-section its
// surfel covers seen against t; add_light.comp.glsl adds a light's sums to the flux atlas.
#include "common/atlas.glsl"

void main() {
    ivec2 t = ivec2(texel);
    vec4 pos = texelFetch(rsm_position, t, 0);
    vec4 nrm = texelFetch(rsm_normal, t, 0);
    vec3 n = nrm.xyz;
    vec4 phi_area = vec4(texelFetch(rsm_flux, t, 0).rgb, nrm.w / (cell_size * cell_size));
    gl_Position = atlas_splat_position(ivec3(floor((pos.xyz - grid_origin) / cell_size)), pos.w != 0.0, atlas_size);
    v_px = phi_area * max(n.x, 0.0);
    v_nx = phi_area * max(-n.x, 0.0);
    v_py = phi_area * max(n.y, 0.0);
    v_ny = phi_area * max(-n.y, 0.0);
    v_pz = phi_area * max(n.z, 0.0);
    v_nz = phi_area * max(-n.z, 0.0);
}
