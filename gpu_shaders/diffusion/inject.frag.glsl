// Diffusion injection: the VPL's flux on the side it lights, added by (ONE, ONE) blending.
void main() {
    out_plus = v_plus;
    out_minus = v_minus;
}
