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
    v_wrange = vec2(min(min(a.z, b.z), c.z), max(max(a.z, b.z), c.z));
    // The triangle's (u, v) corners for the fragment's exact coverage, identical at all three vertices
    // (so interpolation returns them unchanged): the rotation of (a, b, c) that starts at the corner
    // with the smallest u (then v), which every vertex finds the same.
    bool a_first = a.x < b.x || (a.x == b.x && a.y <= b.y);
    a_first = a_first && (a.x < c.x || (a.x == c.x && a.y <= c.y));
    bool b_first = !a_first && (b.x < c.x || (b.x == c.x && b.y <= c.y));
    vec2 q0 = a_first ? a.xy : (b_first ? b.xy : c.xy);
    vec2 q1 = a_first ? b.xy : (b_first ? c.xy : a.xy);
    vec2 q2 = a_first ? c.xy : (b_first ? a.xy : b.xy);
    v_corners01 = vec4(q0, q1);
    v_corner2 = q2;
    v_albedo = albedo;
    v_emission = emission;
    v_normal = tri_normal;
}
