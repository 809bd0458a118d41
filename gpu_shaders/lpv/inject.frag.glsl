// LPV injection: the point's SH (one RGBA per colour channel), added by (ONE, ONE) blending.
void main() {
    out_r = v_r;
    out_g = v_g;
    out_b = v_b;
}
