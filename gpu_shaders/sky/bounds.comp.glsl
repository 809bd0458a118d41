// Per block of BLOCK x BLOCK texels of each sky direction's tile: the least and greatest depth over the
// 3 x 3 blocks around it (within the tile), so that one fetch bounds every tap of a soft-shadow disc of
// radius <= BLOCK texels centred in the block. A texel with no geometry counts as +inf (nothing blocks).
void main() {
    ivec2 block = ivec2(gl_GlobalInvocationID.xy);
    int blocks_per_tile = tile_texels / BLOCK;
    if (any(greaterThanEqual(block, imageSize(sky_bounds)))) {
        return;
    }
    ivec2 tile0 = (block / blocks_per_tile) * tile_texels;
    ivec2 local = block % blocks_per_tile;
    ivec2 lo = max(local - 1, ivec2(0)) * BLOCK;
    ivec2 hi = min(local + 2, ivec2(blocks_per_tile)) * BLOCK;
    float least = 1e30;
    float greatest = -1e30;
    for (int y = lo.y; y < hi.y; ++y) {
        for (int x = lo.x; x < hi.x; ++x) {
            vec4 d = texelFetch(sky_depth_atlas, tile0 + ivec2(x, y), 0);
            float depth = d.w > 0.0 ? d.x : 1e30;
            least = min(least, depth);
            greatest = max(greatest, depth);
        }
    }
    imageStore(sky_bounds, block, vec4(least, greatest, 0.0, 0.0));
}
