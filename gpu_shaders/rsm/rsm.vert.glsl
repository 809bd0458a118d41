// Reflective shadow map (Dachsbacher & Stamminger 2005): the scene seen from one light face.
void main() {
    gl_Position = light_view_projection * vec4(pos_ws, 1.0);
    v_pos_ws = pos_ws;
    v_plane_ws = plane_ws;
    v_normal_ws = normal_ws;
    v_albedo = bounce_albedo;  // toward other surfaces (Scene.bounce_albedo; textured: its texels' factor)
    v_albedo_rect = albedo_rect;
    v_albedo_uv = albedo_uv;
}
