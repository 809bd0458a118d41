// VCT injection: the point's six directional fluxes, added by (ONE, ONE) blending.
void main() {
    out_px = vec4(v_pos, 0.0);
    out_nx = vec4(v_neg, 0.0);
    out_py = vec4(v_pos_y, 0.0);
    out_ny = vec4(v_neg_y, 0.0);
    out_pz = vec4(v_pos_z, 0.0);
    out_nz = vec4(v_neg_z, 0.0);
}
