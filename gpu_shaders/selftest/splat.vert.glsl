// Backend self-test: one point per vertex at a voxel centre of one layer, carrying a value.
void main() {
    gl_Position = vec4(pos_ndc, 0.0, 1.0);
    v_value = value;
}
