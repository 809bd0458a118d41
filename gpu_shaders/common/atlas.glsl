// The layers-as-tiles atlas (passes/atlas.py): z-layer z of a grid of `dims` cells is tile
// (z % tiles_x, z / tiles_x) of one 2D texture, one texel per cell (uniforms dims, tiles_x). Injections
// splat VPLs into it with one point draw; compute passes read it back by cell.

ivec2 atlas_texel(ivec3 c) {
    return ivec2(c.z % tiles_x, c.z / tiles_x) * dims.xy + c.xy;
}

// Clip-space position of a point splat into cell c's texel of an atlas of `size` texels, or a position
// outside the clip volume (the point is dropped) when the VPL is empty or c lies outside the grid. The
// atlas may hold the grid's layers several times over (passes/atlas.py: blocks); the splat goes into the
// copy whose first layer is layer0.
vec4 atlas_splat_position_at(ivec3 c, int layer0, bool valid, ivec2 size) {
    bool inside = all(greaterThanEqual(c, ivec3(0))) && all(lessThan(c, dims));
    if (!valid || !inside) {
        return vec4(2.0, 2.0, 2.0, 1.0);
    }
    vec2 px = vec2(atlas_texel(c + ivec3(0, 0, layer0))) + 0.5;
    return vec4(px / vec2(size) * 2.0 - 1.0, 0.0, 1.0);
}

vec4 atlas_splat_position(ivec3 c, bool valid, ivec2 size) {
    return atlas_splat_position_at(c, 0, valid, size);
}
