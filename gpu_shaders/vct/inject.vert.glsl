// VCT injection: one point per RSM texel (a VPL of reflected flux phi, W, and normal n) splatted into
// its cell's texel of the flux atlas (common/atlas.glsl). Six outputs, one per axis direction t of travel
// (+x, -x, +y, -y, +z, -z): phi * max(0, n.t), the part of the Lambertian VPL's light leaving along t
// (its projection on the axis lobes; level0.comp.glsl turns it into premultiplied radiance).
#include "common/atlas.glsl"

void main() {
    ivec2 t = ivec2(texel);
    vec4 pos = texelFetch(rsm_position, t, 0);
    vec3 n = texelFetch(rsm_normal, t, 0).xyz;
    vec3 phi = texelFetch(rsm_flux, t, 0).rgb;
    gl_Position = atlas_splat_position(ivec3(floor((pos.xyz - grid_origin) / cell_size)), pos.w != 0.0, atlas_size);
    v_px = phi * max(n.x, 0.0);
    v_nx = phi * max(-n.x, 0.0);
    v_py = phi * max(n.y, 0.0);
    v_ny = phi * max(-n.y, 0.0);
    v_pz = phi * max(n.z, 0.0);
    v_nz = phi * max(-n.z, 0.0);
}
