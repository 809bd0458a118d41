void main() {
    float len_n = length(v_normal_ws);
    out_position = vec4(v_pos_ws, 1.0);
    out_normal = vec4(len_n > 0.0 ? v_normal_ws / len_n : vec3(0.0, 0.0, 1.0), 0.0);
    out_albedo = vec4(v_albedo, 1.0);
}
