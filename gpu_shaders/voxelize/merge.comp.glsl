// Merges the three axis volumes (each stored with its slab axis as layers) into the canonical grid and
// divides out the weights: albedo (rgb, a = occupancy 0/1), normal (xyz unit or 0, w = surface area
// in cell units^2), emission (rgb radiance, a = occupancy); projected (per axis, the larger of the
// areas projected by the surfaces facing + and - along it, max(P+, P-) = (sum area |n| + |sum area n|)
// / 2, cell units^2; w = area); offset (per axis a, the area-weighted mean position along a, from the
// cell's centre in cells, of the surfaces voxelized along a, i.e. those facing mostly along a: where in
// the cell a wall lies, which LPV's geometry volume needs to know which face's transfers it blocks; 0
// where the cell has no such surface). A line of sight crosses a closed object's surface twice: the sum of
// |n| counted a thin column twice, and VCT's opacity with it; a one-sided wall keeps its whole area.

ivec3 permuted(ivec3 c, int axis) {
    return axis == 0 ? c.yzx : (axis == 1 ? c.zxy : c);
}

void main() {
    ivec3 c = ivec3(gl_GlobalInvocationID);
    if (any(greaterThanEqual(c, dims))) {
        return;
    }
    vec4 a = texelFetch(albedo_x, permuted(c, 0), 0) + texelFetch(albedo_y, permuted(c, 1), 0)
           + texelFetch(albedo_z, permuted(c, 2), 0);
    vec4 n = texelFetch(normal_x, permuted(c, 0), 0) + texelFetch(normal_y, permuted(c, 1), 0)
           + texelFetch(normal_z, permuted(c, 2), 0);
    vec4 ex = texelFetch(emission_x, permuted(c, 0), 0);
    vec4 ey = texelFetch(emission_y, permuted(c, 1), 0);
    vec4 ez = texelFetch(emission_z, permuted(c, 2), 0);
    vec4 e = ex + ey + ez;
    // Per axis volume its own weight (albedo alpha) divides the depth sum in its emission alpha.
    vec3 axis_weight = vec3(texelFetch(albedo_x, permuted(c, 0), 0).w, texelFetch(albedo_y, permuted(c, 1), 0).w,
                            texelFetch(albedo_z, permuted(c, 2), 0).w);
    vec3 depth_sum = vec3(ex.w, ey.w, ez.w);
    vec4 p = texelFetch(projected_x, permuted(c, 0), 0) + texelFetch(projected_y, permuted(c, 1), 0)
           + texelFetch(projected_z, permuted(c, 2), 0);
    float weight = a.w;
    if (weight <= 0.0) {
        imageStore(vox_albedo, c, vec4(0.0));
        imageStore(vox_normal, c, vec4(0.0));
        imageStore(vox_emission, c, vec4(0.0));
        imageStore(vox_projected, c, vec4(0.0));
        imageStore(vox_offset, c, vec4(0.0));
        return;
    }
    float len_n = length(n.xyz);
    imageStore(vox_albedo, c, vec4(a.rgb / weight, 1.0));
    imageStore(vox_normal, c, vec4(len_n > 1e-6 * weight ? n.xyz / len_n : vec3(0.0), weight));
    imageStore(vox_emission, c, vec4(e.rgb / weight, 1.0));
    imageStore(vox_projected, c, vec4(0.5 * (p.xyz + abs(n.xyz)), p.w));
    vec3 offset = vec3(greaterThan(axis_weight, vec3(0.0))) * depth_sum / max(axis_weight, vec3(1e-30));
    imageStore(vox_offset, c, vec4(clamp(offset, -0.5, 0.5), 0.0));
}
