// Voxelization, one slab of one axis (Mavridis et al.'s slicing, with conservative coverage).
// The triangle is projected along its dominant axis `axis` onto the grid's (u, v) plane, one pixel
// per cell. Every vertex carries its two neighbours so it can grow the triangle conservatively
// (common/conservative.glsl); the fragment shader clips the over-grown corners with its bounding box.
#include "common/conservative.glsl"

vec3 to_uvw(vec3 p_ws) {
    vec3 g = (p_ws - grid_origin) / cell_size;
    return axis == 0 ? g.yzx : (axis == 1 ? g.zxy : g);
}

void main() {
    vec3 a = to_uvw(pos_ws);
    vec3 b = to_uvw(next_ws);
    vec3 c = to_uvw(prev_ws);
    vec2 uv_dims = vec2(axis == 0 ? dims.yz : (axis == 1 ? dims.zx : dims.xy));

    vec2 uv = conservative_corner(a.xy, b.xy, c.xy);

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
