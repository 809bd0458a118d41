// A raster pass's interpolated world position put back on its triangle's plane (plane: unit normal,
// offset d with n . x = d; methods/direct.face_planes; zeros for a degenerate triangle: left as is).
// Seen at a grazing angle (a probe level with a panel) the rasterizer's interpolation leaves a position
// up to 4e-4 of its distance off its plane (measured on the emissive scene's probe atlas), where a
// glowing polygon of that plane fills its hemisphere (common/polygon.glsl); back on the plane it is
// within a few ulps.
vec3 on_face_plane(vec3 p, vec4 plane) {
    return p - (dot(plane.xyz, p) - plane.w) * plane.xyz;
}
