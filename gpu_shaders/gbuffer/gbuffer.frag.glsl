#include "common/face_plane.glsl"
#include "common/albedo_texture.glsl"

// Cycles shades both sides of a surface and, at a back face, flips the normal towards the viewer; do
// the same so back faces seen by the camera receive light like Cycles' Diffuse passes. Which side is
// seen is the triangle's own (face_side): a smooth normal may lean away from the camera on a face that
// faces it (a long wall triangle whose corners' normals lean into the walls beside it), and Cycles
// keeps it so.
void main() {
    vec3 p = on_face_plane(v_pos_ws, v_plane_ws);
    vec3 n = normalize(v_normal_ws) * face_side(v_plane_ws, normalize(v_normal_ws), camera_pos_ws - p);
    out_position = vec4(p, 1.0);  // w = 1 marks geometry (coverage)
    out_normal = vec4(n, 0.0);
    // A textured Base Color: the texel under the pixel's centre times the material's other factors.
    // (A textured triangle's v_albedo is that factor.)
    vec3 albedo = v_albedo_rect.z != 0.0
        ? clamp(albedo_texture(albedo_atlas, v_albedo_rect, v_albedo_uv) * v_albedo, 0.0, 1.0)
        : v_albedo;
    out_albedo = vec4(albedo, 1.0);
    out_specular = v_specular;
}
