// A raster pass's interpolated world position put back on its triangle's plane (plane: unit normal,
// offset d with n . x = d; methods/direct.face_planes; zeros for a degenerate triangle: left as is).
// Seen at a grazing angle (a probe level with a panel) the rasterizer's interpolation leaves a position
// up to 4e-4 of its distance off its plane (measured on the emissive scene's probe atlas), where a
// glowing polygon of that plane fills its hemisphere (common/polygon.glsl); back on the plane it is
// within a few ulps.
vec3 on_face_plane(vec3 p, vec4 plane) {
    return p - (dot(plane.xyz, p) - plane.w) * plane.xyz;
}

// +1 where `to_viewer` (from the surface towards whoever looks: a camera, a probe, a light) is on the
// side of the triangle's plane its normal points to, -1 on the other side. Cycles decides a back face
// by the geometric normal and then flips the shading normal with it; the shading normal `n` decides
// only for a degenerate triangle (no plane).
float face_side(vec4 plane, vec3 n, vec3 to_viewer) {
    vec3 facing = dot(plane.xyz, plane.xyz) > 0.0 ? plane.xyz : n;
    return dot(facing, to_viewer) < 0.0 ? -1.0 : 1.0;
}
