void main() {
    frag_color = v_value;
}
