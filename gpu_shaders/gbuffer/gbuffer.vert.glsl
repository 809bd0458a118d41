// Camera G-buffer: world-space position, normal, diffuse albedo and glossy lobe per pixel.
void main() {
    gl_Position = view_projection * vec4(pos_ws, 1.0);
    v_pos_ws = pos_ws;
    v_plane_ws = plane_ws;
    v_normal_ws = normal_ws;
    v_albedo = albedo;
    v_specular = specular;
    v_albedo_rect = albedo_rect;
    v_albedo_uv = albedo_uv;
}
