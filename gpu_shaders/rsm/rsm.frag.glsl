// Each RSM texel is a VPL: position, normal (facing the light) and reflected flux (W).
// Flux = albedo * I(w) * texel solid angle (perspective: texel_scale * cos^3 of the angle to the face
// axis, no 1/r^2) or albedo * E * texel area (sun: texel_scale = texel area in m^2).
#include "common/light.glsl"

void main() {
    vec3 n = normalize(v_normal_ws);
    vec3 flux;
    if (light_kind == LIGHT_SUN) {
        if (dot(n, emit_axis) > 0.0) {
            n = -n;
        }
        flux = v_albedo * light_color_intensity * texel_scale;
    } else {
        vec3 w = normalize(v_pos_ws - light_pos_ws);
        if (dot(n, w) > 0.0) {
            n = -n;
        }
        float cos_face = max(dot(w, face_axis), 1e-6);
        float solid_angle = texel_scale * cos_face * cos_face * cos_face;
        flux = v_albedo * light_intensity(light_kind, w, emit_axis, light_color_intensity, spot_cos_half, spot_blend) * solid_angle;
    }
    out_position = vec4(v_pos_ws, 1.0);
    out_normal = vec4(n, 0.0);
    out_flux = vec4(flux, 0.0);
}
