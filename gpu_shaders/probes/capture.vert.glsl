// One probe face: world-space position, normal and bounce albedo (Scene.bounce_albedo: how a surface
// reflects toward others) per vertex, projected by the face's view-projection into its viewport of
// the atlas (probe_capture.run).
void main() {
    gl_Position = view_projection * vec4(pos_ws, 1.0);
    v_pos_ws = pos_ws;
    v_plane_ws = plane_ws;
    v_normal_ws = normal_ws;
    v_albedo = bounce_albedo;
}
