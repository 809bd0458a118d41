// VCT injection: the point's six directional fluxes and lit areas, added by (ONE, ONE) blending.
void main() {
    out_px = v_px;
    out_nx = v_nx;
    out_py = v_py;
    out_ny = v_ny;
    out_pz = v_pz;
    out_nz = v_nz;
}
