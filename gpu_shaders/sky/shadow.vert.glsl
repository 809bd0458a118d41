// One sky direction's shadow map: the scene seen along the direction (orthographic), drawn into the
// direction's tile of the sky atlas (the draw's viewport).
void main() {
    gl_Position = light_view_projection * vec4(pos_ws, 1.0);
    v_depth = dot(pos_ws, emit_axis);
}
