// Debug view of the voxel grid on the surfaces the camera sees: each G-buffer pixel shows the albedo
// of the voxel holding its surface point, shaded light/dark by the voxel's checkerboard parity so
// cells are visible; a surface point whose voxel is empty (a hole in the voxelization) is magenta.
void main() {
    ivec2 px = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(px, textureSize(gbuf_position, 0)))) {
        return;
    }
    vec4 pos = texelFetch(gbuf_position, px, 0);
    if (pos.w == 0.0) {
        imageStore(view, px, vec4(0.0));
        return;
    }
    ivec3 c = ivec3(floor((pos.xyz - grid_origin) / cell_size));
    vec4 voxel = all(greaterThanEqual(c, ivec3(0))) && all(lessThan(c, grid_dims))
        ? texelFetch(vox_albedo, c, 0) : vec4(0.0);
    float parity = float((c.x + c.y + c.z) & 1);
    vec3 color = voxel.a > 0.5 ? voxel.rgb * (0.7 + 0.3 * parity) : vec3(1.0, 0.0, 1.0);
    imageStore(view, px, vec4(color, 1.0));
}
