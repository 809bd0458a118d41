// Shadow-mapped direct diffuse light of one light face at every G-buffer pixel, added to `direct` (or in
// its place: `accumulate`, main()).
// Output unit: Cycles' Diffuse Direct pass = irradiance / pi (W/m^2/sr per unit albedo).
// Compiled per kind of light (passes/direct_light.py): POLYGONS for a light with its shape, SOFT_SUN for
// a sun with an angle. llvmpipe pays for a branch's code even where no invocation takes it: a spot
// shaded 1.1 M probe atlas texels in ~270 ms with both, ~60 ms without (docs/PROBES.md).
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

#ifdef SOFT_SUN
// Soft sun shadows (percentage-closer soft shadows): a sun of angular diameter 2 atan(sun_tan_half)
// casts a penumbra (receiver depth - blocker depth) x sun_tan_half wide on each side. The mean depth of
// the blockers found in a disc of the widest penumbra sizes the filter; the lit share of a disc that
// wide is the visibility. Both discs are SOFT_SAMPLES texels on a Vogel spiral (fixed: no per-pixel
// noise). A world region (world.py) is such a sun, as wide as its share of the sky.
const int SOFT_SAMPLES = 16;
const float MAX_SOFT_TEXELS = 16.0;

vec2 vogel(int i) {
    float r = sqrt((float(i) + 0.5) / float(SOFT_SAMPLES));
    float a = float(i) * 2.39996323;
    return r * vec2(cos(a), sin(a));
}

float sun_depth(vec2 uv, ivec2 size) {
    vec4 occ = texelFetch(rsm_position, clamp(ivec2(uv), ivec2(0), size - 1), 0);
    return occ.w > 0.0 ? dot(occ.xyz, emit_axis) : 1e30;  // no geometry: nothing blocks
}

// The receiver's own plane seen from the sun: its depth change per texel of the shadow map, so a disc
// sample is compared with the plane's depth there, not the centre's (else a surface the sun lights at
// a slant shadows itself across the disc). From two tangents of the plane, their texel steps a, b and
// depth steps da, db: depth(delta) = [da db] [a b]^-1 delta.
vec2 receiver_slope(vec3 n, ivec2 size) {
    vec3 t1 = normalize(cross(n, abs(n.x) < 0.9 ? vec3(1.0, 0.0, 0.0) : vec3(0.0, 1.0, 0.0)));
    vec3 t2 = cross(n, t1);
    vec2 a = (light_view_projection * vec4(t1, 0.0)).xy * 0.5 * vec2(size);
    vec2 b = (light_view_projection * vec4(t2, 0.0)).xy * 0.5 * vec2(size);
    float da = dot(t1, emit_axis);
    float db = dot(t2, emit_axis);
    float det = a.x * b.y - a.y * b.x;
    if (abs(det) < 1e-12) {
        return vec2(0.0);  // the sun grazes the surface: it receives (almost) nothing anyway
    }
    return vec2(b.y * da - a.y * db, a.x * db - b.x * da) / det;
}

// A texel with no geometry lies outside everything the sun sees. Taken as lit, it lets a disc that
// reaches past a closed room's outer walls light the room's inside; it counts as the centre does.
float soft_sun_visibility(vec2 uv, ivec2 size, float receiver, float bias_m, float texel_m, vec3 n) {
    vec2 slope = receiver_slope(n, size);
    float centre_lit = sun_depth(uv, size) >= receiver - bias_m ? 1.0 : 0.0;
    float search = min(MAX_SOFT_TEXELS, sun_tan_half * float(size.x));
    float blockers = 0.0;
    float depth_sum = 0.0;
    for (int i = 0; i < SOFT_SAMPLES; ++i) {
        vec2 offset = search * vogel(i);
        float d = sun_depth(uv + offset, size);
        if (d < receiver + dot(slope, offset) - bias_m) {
            blockers += 1.0;
            depth_sum += d;
        }
    }
    if (blockers == 0.0) {
        return 1.0;
    }
    float radius = clamp((receiver - depth_sum / blockers) * sun_tan_half / texel_m, 0.5, MAX_SOFT_TEXELS);
    float lit = 0.0;
    for (int i = 0; i < SOFT_SAMPLES; ++i) {
        vec2 offset = radius * vogel(i);
        float d = sun_depth(uv + offset, size);
        lit += d >= 1e29 ? centre_lit : (d >= receiver + dot(slope, offset) - bias_m ? 1.0 : 0.0);
    }
    return lit / float(SOFT_SAMPLES);
}
#endif

// This face's direct light (irradiance / pi) at G-buffer pixel px, which sees geometry: 0 where
// another face shades it, where the light does not reach it, or in its shadow.
vec3 face_light(ivec2 px, vec4 pos) {
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
#ifndef POLYGONS
        vec3 intensity = light_intensity(light_kind, w, emit_axis, light_color_intensity, spot_cos_half,
                                         spot_blend);
        irradiance = intensity * max(dot(n, to_light), 0.0) / max(dist * dist, 1e-12);
#endif
        texel_m = sqrt(texel_scale) * dist;
    }
#ifndef POLYGONS
    if (all(equal(irradiance, vec3(0.0)))) {
        return vec3(0.0);
    }
#endif
    // Shadow test against the RSM's stored positions. The receiver is pushed off its surface by 1.5 RSM
    // texels along its normal (normal-offset bias) so it does not shadow itself; every bias is in
    // texels, so the result does not depend on the scene's scale.
    vec3 p_test = p + n * (1.5 * texel_m);
    float bias_m = shadow_bias_texels * texel_m;
    if (face_index >= 0 && cube_face(p_test - light_pos_ws) != face_index) {
        return vec3(0.0);  // another face of this point light shades this pixel: the one p_test projects into
    }
#ifdef POLYGONS
    // A light with its shape (an area light's patch, an emissive mesh's triangles; never a sun): the
    // exact unshadowed irradiance of its polygons, after the face test, so that only the face that
    // shades this pixel pays for the integral; light_pos_ws is where its shadow is taken from.
    irradiance = emitter_irradiance(emitters, poly_first, poly_count, p, n);
    if (all(equal(irradiance, vec3(0.0)))) {
        return vec3(0.0);
    }
#endif
    vec4 clip = light_view_projection * vec4(p_test, 1.0);
    vec3 ndc = clip.xyz / clip.w;
    float lit = 1.0;
    if (clip.w > 0.0 && all(lessThanEqual(abs(ndc.xy), vec2(1.0)))) {
        ivec2 size = textureSize(rsm_position, 0);
#ifdef SOFT_SUN
        lit = soft_sun_visibility((ndc.xy * 0.5 + 0.5) * vec2(size), size, dot(p_test, emit_axis), bias_m, texel_m,
                                  n);
#else
        ivec2 texel = clamp(ivec2((ndc.xy * 0.5 + 0.5) * vec2(size)), ivec2(0), size - 1);
        vec4 occ = texelFetch(rsm_position, texel, 0);
        if (occ.w > 0.0) {
            float receiver = light_kind == LIGHT_SUN ? dot(p_test, emit_axis) : length(p_test - light_pos_ws);
            float occluder = light_kind == LIGHT_SUN ? dot(occ.xyz, emit_axis) : length(occ.xyz - light_pos_ws);
            lit = receiver <= occluder + bias_m ? 1.0 : 0.0;
        }
#endif
    }
    return irradiance * (lit / PI);
}

// Adds this face's light to `direct`, or with accumulate = 0 (a solve's first face on the probe atlas)
// puts it in place of what `direct` holds, so that the atlas needs no zeroing pass before each solve
// (texels that see no geometry are never written: 0 since set-up). One store, after the shading: a
// store on each of its early ways out cost llvmpipe a third more time.
void main() {
    ivec2 px = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(px, textureSize(gbuf_position, 0)))) {
        return;
    }
    vec4 pos = texelFetch(gbuf_position, px, 0);
    if (pos.w == 0.0) {
        return;
    }
    vec3 light = face_light(px, pos);
    if (accumulate != 0 && all(equal(light, vec3(0.0)))) {
        return;
    }
    vec4 acc = accumulate != 0 ? imageLoad(direct, px) : vec4(0.0);
    imageStore(direct, px, acc + vec4(light, 0.0));
}
