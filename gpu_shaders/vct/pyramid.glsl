// The radiance pyramid's layout, shared by the passes that write and read it (vct_pyramid.py).
// Six RGBA16F 3D textures, one per axis direction t of travel (px, nx, py, ny, pz, nz), each holding
// every level side by side along x: level l (dims_l = ceil(dims / 2^l)) at x offset 2P - 2P / 2^l,
// P = dims.x rounded up to a power of two (so level l fits in P / 2^l texels; no loop to sum sizes).
// rgb = premultiplied radiance (W/m^2/sr averaged over the cell's cross-section) x radiance_scale
// (vct_pyramid.radiance_scale, for half floats' range), a = opacity, both
// as seen by a ray travelling along -t (i.e. light travelling along t towards the viewer).

ivec3 level_dims(ivec3 dims0, int level) {
    int s = (1 << level) - 1;
    return (dims0 + ivec3(s)) >> level;
}

int level_offset(ivec3 dims0, int level) {
    int two_p = 2 << (findMSB(dims0.x - 1) + 1);
    return two_p - (two_p >> level);
}
