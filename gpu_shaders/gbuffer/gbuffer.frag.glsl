#include "common/face_plane.glsl"

// Cycles shades both sides of a surface and flips the normal towards the viewer at a back face;
// do the same so back faces seen by the camera receive light like Cycles' Diffuse passes.
void main() {
    vec3 p = on_face_plane(v_pos_ws, v_plane_ws);
    vec3 n = normalize(v_normal_ws);
    if (dot(n, camera_pos_ws - p) < 0.0) {
        n = -n;
    }
    out_position = vec4(p, 1.0);  // w = 1 marks geometry (coverage)
    out_normal = vec4(n, 0.0);
    out_albedo = vec4(v_albedo, 1.0);
    out_specular = v_specular;
}
