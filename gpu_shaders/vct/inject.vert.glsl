// VCT injection: RSM texels (VPLs of reflected flux phi, W, normal n, surfel area A) splatted into a
// light's scratch atlas (common/atlas.glsl). Six outputs, one per axis direction t of travel (+x, -x,
// +y, -y, +z, -z): (phi, A / h^2) * max(0, n.t), the part of the Lambertian VPL's light leaving along t
// (its projection on the axis lobes) and the cross-section its surfel covers seen against t;
// add_light.comp.glsl adds a light's sums to the flux atlas.
//
// FILTERED_INJECTION (VctConfig.filtered_injection; vct_inject.filtered_cells is the twin): four points
// per texel. The VPL goes to the cell layer holding it along its normal's dominant axis a, and is
// shared bilinearly between the 2 x 2 cells whose centres surround it in the two other axes, each
// weight kept only where that cell holds geometry facing a (vox_projected) and the kept ones
// renormalised: its flux moves continuously as a light moves (a point splat moved all of it one cell
// when it crossed a cell border: a light moving 1 mm per frame flickered by 1.1 %), stays on its side
// of the surface, and goes to no cell without a surface. Otherwise one point, into the VPL's cell.
#include "common/atlas.glsl"
#include "lpv/emitter_class.glsl"

#ifdef FILTERED_INJECTION
// Cell of corner ij of the 2 x 2 block: `layer` along axis a, base + ij along the two others in order.
ivec3 corner_cell(int a, int layer, ivec2 base, ivec2 ij) {
    ivec2 c = base + ij;
    if (a == 0) return ivec3(layer, c.x, c.y);
    if (a == 1) return ivec3(c.x, layer, c.y);
    return ivec3(c.x, c.y, layer);
}

// Bilinear weight of corner ij for fractions f, or 0 where that cell holds no geometry facing axis a
// (its projected area along a, cells^2; 0 outside the grid).
float kept_weight(int a, int layer, ivec2 base, ivec2 ij, vec2 f) {
    ivec3 c = corner_cell(a, layer, base, ij);
    if (any(lessThan(c, ivec3(0))) || any(greaterThanEqual(c, dims))) return 0.0;
    if (texelFetch(vox_projected, c, 0)[a] <= 0.0) return 0.0;
    return (ij.x == 1 ? f.x : 1.0 - f.x) * (ij.y == 1 ? f.y : 1.0 - f.y);
}
#endif

void main() {
    ivec2 t = ivec2(texel);
    vec4 pos = texelFetch(rsm_position, t, 0);
    vec4 nrm = texelFetch(rsm_normal, t, 0);
    vec3 n = nrm.xyz;
    vec3 g = (pos.xyz - grid_origin) / cell_size;  // position in cells
    ivec3 cell = ivec3(floor(g));
    float weight = 1.0;
#ifdef FILTERED_INJECTION
    int corner = gl_VertexID % 4;  // atlas.texel_points(copies=4): each texel four times in a row
    int a = emitter_class(n) / 2;
    int layer = cell[a];
    vec2 across = (a == 0 ? g.yz : (a == 1 ? g.xz : g.xy)) - 0.5;  // from the cell centres
    ivec2 base = ivec2(floor(across));
    vec2 f = across - vec2(base);
    float total = 0.0;
    float own = 0.0;
    for (int k = 0; k < 4; k++) {
        float w = kept_weight(a, layer, base, ivec2(k & 1, k >> 1), f);
        total += w;
        own += k == corner ? w : 0.0;
    }
    if (total > 0.0) {
        cell = corner_cell(a, layer, base, ivec2(corner & 1, corner >> 1));
        weight = own / total;
    } else {
        // No such cell (the voxelizer missed a sliver): all of it in its own cell, from one corner.
        weight = corner == 0 ? 1.0 : 0.0;
    }
#endif
    vec4 phi_area = vec4(texelFetch(rsm_flux, t, 0).rgb, nrm.w / (cell_size * cell_size)) * weight;
    gl_Position = atlas_splat_position(cell, pos.w != 0.0 && weight > 0.0, atlas_size);
    v_px = phi_area * max(n.x, 0.0);
    v_nx = phi_area * max(-n.x, 0.0);
    v_py = phi_area * max(n.y, 0.0);
    v_ny = phi_area * max(-n.y, 0.0);
    v_pz = phi_area * max(n.z, 0.0);
    v_nz = phi_area * max(-n.z, 0.0);
}
