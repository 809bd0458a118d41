// LPV far field, geometry: the coarse grid's projected areas and surface offsets from its 2 x 2 x 2 fine
// cells, so the far field blocks light where the fine grid's voxels say, without a second voxelization.
// Projected area along an axis (cells^2): the children's sum / 4 (a coarse cell's cross-section is four
// fine ones: a wall across the coarse cell covers 2 x 2 children of area 1 -> 1). Offset along an axis
// (cells from the centre): the children's surface positions, child centre +-0.5 fine cells plus its
// offset, averaged with the child's projected area along that axis as weight, halved into coarse cells;
// 0 where no child has a surface facing that axis. Fine cells beyond odd fine dims hold nothing.

void main() {
    ivec3 c = ivec3(gl_GlobalInvocationID);
    if (any(greaterThanEqual(c, dims))) {
        return;
    }
    vec3 area = vec3(0.0);
    vec3 moment = vec3(0.0);
    float surface = 0.0;
    for (int k = 0; k < 8; ++k) {
        ivec3 corner = ivec3(k & 1, (k >> 1) & 1, k >> 2);
        ivec3 child = 2 * c + corner;
        if (any(greaterThanEqual(child, fine_dims))) {
            continue;
        }
        vec4 p = texelFetch(fine_projected, child, 0);
        vec3 position = vec3(corner) - 0.5 + texelFetch(fine_offset, child, 0).xyz;  // fine cells from c's centre
        area += p.xyz;
        moment += p.xyz * position;
        surface += p.w;
    }
    vec3 offset = mix(vec3(0.0), 0.5 * moment / max(area, vec3(1e-30)), greaterThan(area, vec3(0.0)));
    imageStore(vox_projected, c, vec4(0.25 * area, 0.25 * surface));
    imageStore(vox_offset, c, vec4(offset, 0.0));
}
