// VCT injection: the point's six directional fluxes, added by (ONE, ONE) blending.
void main() {
    out_px = vec4(v_px, 0.0);
    out_nx = vec4(v_nx, 0.0);
    out_py = vec4(v_py, 0.0);
    out_ny = vec4(v_ny, 0.0);
    out_pz = vec4(v_pz, 0.0);
    out_nz = vec4(v_nz, 0.0);
}
