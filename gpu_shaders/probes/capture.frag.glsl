#include "common/face_plane.glsl"

// One probe face's G-buffer texel (probes/capture.vert.glsl projects it with the face's
// view-projection into the face's viewport of the atlas). The normal is flipped where the probe sees
// the triangle's back (surfaces are two-sided, as in Cycles); its w records which side the probe sees:
// +1 the front (the side the triangle's normal points to), -1 the back -- a probe inside a closed
// object sees back faces only (probe_capture.classify).
void main() {
    vec3 p = on_face_plane(v_pos_ws, v_plane_ws);
    vec3 n = normalize(v_normal_ws);
    float side = face_side(v_plane_ws, n, camera_pos_ws - p);  // the triangle's side, as Cycles decides it
    n *= side;
    out_position = vec4(p, 1.0);  // w = 1 marks geometry
    out_normal = vec4(n, side);
    out_albedo = vec4(v_albedo, 1.0);
}
