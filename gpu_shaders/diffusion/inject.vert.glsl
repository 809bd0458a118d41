// Diffusion injection: one point per RSM texel (a VPL of flux phi, W) into the cell holding its surface,
// on the side of that cell's plane its normal faces (the plus side: where cell_normal points). A VPL
// whose cell is empty (its surface on a cell border, fp32 rounding picked the neighbour) goes to the
// cell half a cell behind it when that one is occupied. Added to the texel of the cell in the atlases
// (passes/atlas.py); empty texels and points outside the grid are clipped.
#include "common/atlas.glsl"
#include "diffusion/cell.glsl"

vec4 cell_at(ivec3 c) {
    return diffusion_inside(c) ? texelFetch(cell_normal, c, 0) : vec4(0.0);
}

void main() {
    ivec2 t = ivec2(texel);
    vec4 pos = texelFetch(rsm_position, t, 0);
    vec3 n = texelFetch(rsm_normal, t, 0).xyz;
    vec3 phi = texelFetch(rsm_flux, t, 0).rgb;
    vec3 g = (pos.xyz - grid_origin) / cell_size;
    ivec3 c = ivec3(floor(g));
    vec4 plane = cell_at(c);
    if (plane.w <= 0.0) {
        ivec3 behind = ivec3(floor(g - 0.5 * n));
        vec4 behind_plane = cell_at(behind);
        if (behind_plane.w > 0.0) {
            c = behind;
            plane = behind_plane;
        }
    }
    gl_Position = atlas_splat_position(c, pos.w != 0.0, atlas_size);
    bool plus = dot(n, plane.xyz) >= 0.0;
    v_plus = plus ? vec4(phi, 0.0) : vec4(0.0);
    v_minus = plus ? vec4(0.0) : vec4(phi, 0.0);
}
