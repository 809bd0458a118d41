// Texel G-buffer of points (vertex-colour bakes): one texel per sample at integer coordinates `texel`.
void main() {
    gl_Position = vec4((texel + 0.5) / texel_size * 2.0 - 1.0, 0.0, 1.0);
    v_pos_ws = pos_ws;
    v_normal_ws = normal_ws;
    v_albedo = albedo;
}
