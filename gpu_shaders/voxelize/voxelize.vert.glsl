// Voxelization, one slab of one axis (Mavridis et al.'s slicing, with conservative coverage).
// The triangle is projected along its dominant axis `axis` onto the grid's (u, v) plane, one pixel
// per cell. Conservative rasterization without geometry shaders: every vertex carries its two
// neighbours, moves its two edges outward by the pixel's half-extent along each edge normal
// (Hasselgren et al., GPU Gems 2 ch. 42) and becomes their intersection; the fragment shader clips
// the over-grown corners with the triangle's bounding box.

vec3 to_uvw(vec3 p_ws) {
    vec3 g = (p_ws - grid_origin) / cell_size;
    return axis == 0 ? g.yzx : (axis == 1 ? g.zxy : g);
}

void main() {
    vec3 a = to_uvw(pos_ws);
    vec3 b = to_uvw(next_ws);
    vec3 c = to_uvw(prev_ws);
    vec2 uv_dims = vec2(axis == 0 ? dims.yz : (axis == 1 ? dims.zx : dims.xy));

    // Outward edge normals in the (u, v) plane for either winding.
    float orient = sign((b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x));
    vec2 e0 = b.xy - a.xy;  // edge a -> b
    vec2 e1 = a.xy - c.xy;  // edge c -> a
    vec2 n0 = orient * normalize(vec2(e0.y, -e0.x) + 1e-12);
    vec2 n1 = orient * normalize(vec2(e1.y, -e1.x) + 1e-12);
    // Each edge line moves by the half-pixel extent along its normal: 0.5 * (|nx| + |ny|).
    float d0 = 0.5 * (abs(n0.x) + abs(n0.y));
    float d1 = 0.5 * (abs(n1.x) + abs(n1.y));
    // Intersection of (x - a).n0 = d0 and (x - a).n1 = d1; parallel edges (degenerate) keep the vertex.
    float det = n0.x * n1.y - n0.y * n1.x;
    vec2 offset = abs(det) > 1e-6 ? vec2(d0 * n1.y - d1 * n0.y, n0.x * d1 - n1.x * d0) / det : vec2(0.0);
    // A sliver's acute corner moves ~0.7 px / sin(angle / 2) along its bisector; the bounding-box clip
    // in the fragment shader trims the overshoot. Cap the length (keeping the direction) so a
    // near-degenerate triangle cannot cover the whole viewport.
    float len_offset = length(offset);
    offset *= min(1.0, 1024.0 / max(len_offset, 1e-12));
    vec2 uv = a.xy + offset;

    gl_Position = vec4(uv / uv_dims * 2.0 - 1.0, 0.0, 1.0);
    v_uvw = vec3(uv, a.z);
    vec3 n_uvw = axis == 0 ? tri_normal.yzx : (axis == 1 ? tri_normal.zxy : tri_normal);
    v_plane = vec4(n_uvw, dot(n_uvw, a));
    v_bbox = vec4(min(min(a.xy, b.xy), c.xy) - 0.5, max(max(a.xy, b.xy), c.xy) + 0.5);
    float area_px = 0.5 * abs((b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x));
    v_wrange = vec3(min(min(a.z, b.z), c.z), max(max(a.z, b.z), c.z), area_px);
    v_albedo = albedo;
    v_emission = emission;
    v_normal = tri_normal;
}
