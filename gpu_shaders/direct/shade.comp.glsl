// Shadow-mapped direct diffuse light of one light face at every G-buffer pixel, added to `direct`.
// Output unit: Cycles' Diffuse Direct pass = irradiance / pi (W/m^2/sr per unit albedo).
#include "common/light.glsl"
#include "common/polygon.glsl"

const float PI = 3.14159265;

// Point-light faces partition directions by their major axis; face = 2 * axis + (negative ? 1 : 0).
int cube_face(vec3 d) {
    vec3 a = abs(d);
    if (a.x >= a.y && a.x >= a.z) {
        return d.x >= 0.0 ? 0 : 1;
    }
    if (a.y >= a.z) {
        return d.y >= 0.0 ? 2 : 3;
    }
    return d.z >= 0.0 ? 4 : 5;
}

void main() {
    ivec2 px = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(px, textureSize(gbuf_position, 0)))) {
        return;
    }
    vec4 pos = texelFetch(gbuf_position, px, 0);
    if (pos.w == 0.0) {
        return;
    }
    vec3 p = pos.xyz;
    vec3 n = texelFetch(gbuf_normal, px, 0).xyz;
    vec3 irradiance;
    vec3 to_light;
    float dist = 0.0;
    float texel_m;
    if (light_kind == LIGHT_SUN) {
        to_light = -emit_axis;
        irradiance = light_color_intensity * max(dot(n, to_light), 0.0);
        texel_m = sqrt(texel_scale);
    } else {
        vec3 d = p - light_pos_ws;
        dist = length(d);
        vec3 w = d / max(dist, 1e-9);
        to_light = -w;
        if (poly_count > 0) {
            // A light with its shape (an area light's patch, an emissive mesh's triangles): the exact
            // unshadowed irradiance of its polygons; light_pos_ws is where its shadow is taken from.
            irradiance = emitter_irradiance(emitters, poly_first, poly_count, p, n);
        } else {
            vec3 intensity = light_intensity(light_kind, w, emit_axis, light_color_intensity, spot_cos_half,
                                             spot_blend);
            irradiance = intensity * max(dot(n, to_light), 0.0) / max(dist * dist, 1e-12);
        }
        texel_m = sqrt(texel_scale) * dist;
    }
    if (all(equal(irradiance, vec3(0.0)))) {
        return;
    }
    // Shadow test against the RSM's stored positions. The receiver is pushed off its surface by 1.5 RSM
    // texels along its normal (normal-offset bias) so it does not shadow itself; every bias is in
    // texels, so the result does not depend on the scene's scale.
    vec3 p_test = p + n * (1.5 * texel_m);
    float bias_m = shadow_bias_texels * texel_m;
    if (face_index >= 0 && cube_face(p_test - light_pos_ws) != face_index) {
        return;  // another face of this point light shades this pixel: the one p_test projects into
    }
    vec4 clip = light_view_projection * vec4(p_test, 1.0);
    vec3 ndc = clip.xyz / clip.w;
    float lit = 1.0;
    if (clip.w > 0.0 && all(lessThanEqual(abs(ndc.xy), vec2(1.0)))) {
        ivec2 size = textureSize(rsm_position, 0);
        ivec2 texel = clamp(ivec2((ndc.xy * 0.5 + 0.5) * vec2(size)), ivec2(0), size - 1);
        vec4 occ = texelFetch(rsm_position, texel, 0);
        if (occ.w > 0.0) {
            float receiver = light_kind == LIGHT_SUN ? dot(p_test, emit_axis) : length(p_test - light_pos_ws);
            float occluder = light_kind == LIGHT_SUN ? dot(occ.xyz, emit_axis) : length(occ.xyz - light_pos_ws);
            lit = receiver <= occluder + bias_m ? 1.0 : 0.0;
        }
    }
    vec4 acc = imageLoad(direct, px);
    imageStore(direct, px, acc + vec4(irradiance * (lit / PI), 0.0));
}
