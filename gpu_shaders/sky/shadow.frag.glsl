// Depth along the direction's axis (m): what the sky pass compares a receiver with; w = 1 where geometry.
void main() {
    out_depth = vec4(v_depth, 0.0, 0.0, 1.0);
}
