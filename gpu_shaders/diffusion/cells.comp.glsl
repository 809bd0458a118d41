// What the diffusion transport needs of the voxels, per cell (diffusion_reference.cells): cell_normal
// (xyz = the surface's plane, unit: the voxels' mean normal, or where it cancels -- both faces of a thin
// wall in one cell -- the axis the surfaces project the most along; w = each side's receiving area,
// sum over axes of block x (1 where the normal has a component along it, else 1/2), cells^2) and
// cell_block (xyz = per axis min(1, projected area), the share of a face's inflow absorbed; w = 0 empty,
// else 1 + the mask of open faces, those to empty cells or out of the grid (bits 0-5), and of the sides
// light can reach at all, those with a face to an empty cell in the grid (bit 6 plus, 7 minus).
#include "diffusion/cell.glsl"

void main() {
    ivec3 c = ivec3(gl_GlobalInvocationID);
    if (any(greaterThanEqual(c, dims))) {
        return;
    }
    if (texelFetch(vox_albedo, c, 0).a <= 0.0) {
        imageStore(cell_normal, c, vec4(0.0));
        imageStore(cell_block, c, vec4(0.0));
        return;
    }
    vec3 mean = texelFetch(vox_normal, c, 0).xyz;
    vec3 projected = texelFetch(vox_projected, c, 0).xyz;
    vec3 major = projected.x >= projected.y && projected.x >= projected.z ? vec3(1.0, 0.0, 0.0)
               : (projected.y >= projected.z ? vec3(0.0, 1.0, 0.0) : vec3(0.0, 0.0, 1.0));
    vec3 n = length(mean) > 0.5 ? mean : major;
    vec3 block = min(vec3(1.0), projected);
    vec3 share = mix(vec3(0.5), vec3(1.0), greaterThan(abs(n), vec3(DIFFUSION_SIDE_EPSILON)));
    int mask = 0;
    for (int f = 0; f < 6; f++) {
        vec3 d = diffusion_direction(f);
        ivec3 nb = c + ivec3(d);
        bool inside = diffusion_inside(nb);
        if (!inside || texelFetch(vox_albedo, nb, 0).a <= 0.0) {
            mask |= 1 << f;
            if (inside) {  // an empty cell in the grid: light can arrive from it on its side
                float dn = dot(d, n);
                mask |= dn > DIFFUSION_SIDE_EPSILON ? DIFFUSION_RECEIVES_PLUS
                      : (dn < -DIFFUSION_SIDE_EPSILON ? DIFFUSION_RECEIVES_MINUS : 0);
            }
        }
    }
    imageStore(cell_normal, c, vec4(n, dot(block, share)));
    imageStore(cell_block, c, vec4(block, float(1 + mask)));
}
