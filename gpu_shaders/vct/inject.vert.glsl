// VCT injection: one point per RSM texel (a VPL of reflected flux phi, W, normal n, surfel area A)
// splatted into the texel of the flux atlas (common/atlas.glsl) of the cell inject_offset_cells along n from
// it (passes/vct_inject.py says why). Six outputs, one per axis direction t of travel (+x, -x, +y, -y,
// +z, -z): (phi, A / h^2) * max(0, n.t), the part of the Lambertian VPL's light leaving along t (its
// projection on the axis lobes) and the cross-section its surfel covers seen against t;
// level0.comp.glsl turns them into premultiplied radiance and opacity.
#include "common/atlas.glsl"

void main() {
    ivec2 t = ivec2(texel);
    vec4 pos = texelFetch(rsm_position, t, 0);
    vec4 nrm = texelFetch(rsm_normal, t, 0);
    vec3 n = nrm.xyz;
    vec3 phi = texelFetch(rsm_flux, t, 0).rgb;
    vec3 p = pos.xyz + n * (inject_offset_cells * cell_size);
    gl_Position = atlas_splat_position(ivec3(floor((p - grid_origin) / cell_size)), pos.w != 0.0, atlas_size);
    float area = nrm.w / (cell_size * cell_size);
    v_px = vec4(phi, area) * max(n.x, 0.0);
    v_nx = vec4(phi, area) * max(-n.x, 0.0);
    v_py = vec4(phi, area) * max(n.y, 0.0);
    v_ny = vec4(phi, area) * max(-n.y, 0.0);
    v_pz = vec4(phi, area) * max(n.z, 0.0);
    v_nz = vec4(phi, area) * max(-n.z, 0.0);
}
