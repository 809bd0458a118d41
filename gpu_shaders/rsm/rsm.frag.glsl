// Each RSM texel is a VPL: position, normal (facing the light; w = the surfel's area in m^2) and
// reflected flux (W). Flux = albedo * I(w) * texel solid angle (perspective: texel_scale * cos^3 of
// the angle to the face axis, no 1/r^2) or albedo * E * texel area (sun: texel_scale = area in m^2).
// Surfel area = the texel's footprint on the surface: solid angle * r^2 / cos, or area / cos for a sun,
// times area_weight (1; a sky RSM tile's share of the sky's power, passes/sky_light.table).
// The flux's w names the triangle the texel sees, its index in the drawn mesh + 1 (0: none): the direct
// pass's exact shadow test (direct/shade.comp.glsl) intersects the shadow ray with it. A float holds every
// index below 2^24 exactly.
#include "common/albedo_texture.glsl"
#include "common/face_plane.glsl"
#include "common/light.glsl"

void main() {
    vec3 n = normalize(v_normal_ws);
    // A textured Base Color reflects the texel under the texel's centre (times the material's other
    // factors toward a diffuse surface); a flat one its albedo.
    vec3 albedo = v_albedo_rect.z != 0.0
        ? clamp(albedo_texture(albedo_atlas, v_albedo_rect, v_albedo_uv) * v_albedo, 0.0, 1.0)
        : v_albedo;
    vec3 flux;
    float area_m2;
    // Grazing surfels have huge footprints; 0.05 caps them at 20x the texel's cross-section.
    const float MIN_COS = 0.05;
    // The normal faces the light on the side of the triangle the light sees (face_side: as Cycles
    // decides a back face, by the triangle's own normal). The footprint is the triangle's plane's.
    vec3 facing = dot(v_plane_ws.xyz, v_plane_ws.xyz) > 0.0 ? v_plane_ws.xyz : n;
    if (light_kind == LIGHT_SUN) {
        n *= face_side(v_plane_ws, n, -emit_axis);
        flux = albedo * light_color_intensity * texel_scale;
        area_m2 = texel_scale / max(abs(dot(facing, emit_axis)), MIN_COS);
    } else {
        vec3 w = normalize(v_pos_ws - light_pos_ws);
        n *= face_side(v_plane_ws, n, -w);
        float cos_face = max(dot(w, face_axis), 1e-6);
        float solid_angle = texel_scale * cos_face * cos_face * cos_face;
        flux = albedo * light_intensity(light_kind, w, emit_axis, light_color_intensity, spot_cos_half, spot_blend) * solid_angle;
        float dist = length(v_pos_ws - light_pos_ws);
        area_m2 = solid_angle * dist * dist / max(abs(dot(facing, w)), MIN_COS);
        if (occluder_radius > 0.0) {
            // The emitter's own surface, a disc of that radius at the light facing emit_axis, takes the
            // share of the surfel's reflected light that goes back at it: its view factor from the
            // surfel (light_views.disc_view_factor; exact for a surfel parallel to it, weighted by how
            // parallel it is otherwise).
            vec3 d = v_pos_ws - light_pos_ws;
            float h = dot(d, emit_axis);
            float h2 = h * h;
            float a2 = max(dot(d, d) - h2, 0.0);
            float r2 = occluder_radius * occluder_radius;
            float root = sqrt(max((h2 + a2 + r2) * (h2 + a2 + r2) - 4.0 * a2 * r2, 1e-30));
            float view_factor = 0.5 * (1.0 - (h2 + a2 - r2) / root);
            flux *= 1.0 - clamp(view_factor * max(-dot(n, emit_axis), 0.0), 0.0, 1.0);
        }
    }
    out_position = vec4(v_pos_ws, 1.0);
    out_normal = vec4(n, area_m2 * area_weight);
    out_flux = vec4(flux, float(gl_PrimitiveID + 1));
}
