// Shadow-mapped direct diffuse light of one light face at every G-buffer pixel, added to `direct` (or in
// its place: `accumulate`, main()).
// Output unit: Cycles' Diffuse Direct pass = irradiance / pi (W/m^2/sr per unit albedo).
// Compiled per kind of light (passes/direct_light.py): POLYGONS for a light with its shape, SOFT_SUN for
// a sun with an angle. llvmpipe pays for a branch's code even where no invocation takes it: a spot
// shaded 1.1 M probe atlas texels in ~270 ms with both, ~60 ms without (docs/PROBES.md).
#include "common/light.glsl"
#include "common/texel_list.glsl"
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

#if defined(SOFT_SUN) || defined(POLYGONS)
// Soft shadows (percentage-closer soft shadows) of a sun with an angle or a light with a shape: the mean
// depth of the blockers found in a disc as wide as the widest penumbra sizes the filter; the lit share of
// a disc as wide as the penumbra there is the visibility. Both discs are SOFT_SAMPLES texels on a Vogel
// spiral (fixed: no per-pixel noise).
const int SOFT_SAMPLES = 16;
const float MAX_SOFT_TEXELS = 16.0;
// A probe atlas texel shaded at AREA_SAMPLES points (texel_area_light) spends one point's taps over
// them: point s takes the spiral's taps s, s + AREA_SAMPLES, ..., so together they cover the disc as the
// centre's 16 do, and the grazing texels' pass costs about what as many centres do (4 points of
// window-sky-sun's sun with 16 taps each: 68 ms, more than the 630 K other texels' 150 ms).
#ifdef AREA_SAMPLES
const int SOFT_STRIDE = AREA_SAMPLES;
#else
const int SOFT_STRIDE = 1;
#endif
const int SOFT_TAPS = SOFT_SAMPLES / SOFT_STRIDE;  // AREA_SAMPLES <= 16 (ProbesConfig): at least 1
int soft_first = 0;  // the spiral's first tap for the point being shaded

// Tap i of the point being shaded: the spiral's tap soft_first + SOFT_STRIDE i.
vec2 vogel(int i) {
    int j = soft_first + SOFT_STRIDE * i;
    float r = sqrt((float(j) + 0.5) / float(SOFT_SAMPLES));
    float a = float(j) * 2.39996323;
    return r * vec2(cos(a), sin(a));
}
#endif

#ifdef SOFT_SUN
// A sun of angular diameter 2 atan(sun_tan_half) casts a penumbra (receiver depth - blocker depth) x
// sun_tan_half wide on each side. A world region (world.py) is such a sun, as wide as its share of the sky.

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
    for (int i = 0; i < SOFT_TAPS; ++i) {
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
    for (int i = 0; i < SOFT_TAPS; ++i) {
        vec2 offset = radius * vogel(i);
        float d = sun_depth(uv + offset, size);
        lit += d >= 1e29 ? centre_lit : (d >= receiver + dot(slope, offset) - bias_m ? 1.0 : 0.0);
    }
    return lit / float(SOFT_TAPS);
}
#endif

// Whether receiver p lies in front of the plane of the surface a shadow-map texel stores (its position
// and its normal, which the RSM turns towards the light), so that surface cannot block p's light: a real
// blocker crosses the segment from the light to p, so p lies behind its plane, while a wall p stands in
// front of (a floor's last pixels looking up the wall beside them) does not, and a zero-thickness wall
// between p and the light still does (p lies behind the side the light sees). The margin, 1 % of a
// texel, absorbs fp32 rounding at a crease. docs/DIRECT.md, "The shadow test".
bool in_front_of(vec3 p, vec4 occ_position, vec3 occ_normal, float texel_m) {
    return dot(p - occ_position.xyz, occ_normal) >= -0.01 * texel_m;
}

#ifdef POLYGONS
// A light with a shape (an area light's patch, an emissive group) is shadowed from its position c over a
// disc of radius emitter_radius_m facing the receiver. A blocker at distance z_b from c casts, seen from
// c, a penumbra of angular half-width r (1 / z_b - 1 / z_r) around its edge on a receiver at z_r
// (similar triangles through the blocker's edge): in shadow-map texels that over the texel's angle
// sqrt(texel_scale). Depths are distances from c; a disc sample is compared with the receiver's plane
// along its own ray (the plane's distance there), so a surface lit at a slant does not shadow itself.
// Distance from c along the shadow map's ray through texel position uv to the plane through p with
// normal n; `fallback` where the ray meets the plane behind c or nearly parallel to it.
float plane_distance_m(vec2 uv, ivec2 size, vec3 p, vec3 n, float fallback) {
    vec4 far_point = light_view_projection_inverse * vec4(uv / vec2(size) * 2.0 - 1.0, 1.0, 1.0);
    vec3 w = normalize(far_point.xyz / far_point.w - light_pos_ws);
    float along = dot(n, w);
    float t = abs(along) > 1e-6 ? dot(n, p - light_pos_ws) / along : -1.0;
    return t > 0.0 && t < 4.0 * fallback ? t : fallback;
}

// The distance from c of the surface at texel position uv if it blocks receiver p (whose plane through
// p_test, normal n, lies receiver_m away at the centre), else -1; 1e30 where the texel has no geometry.
// It blocks when it is nearer c than the receiver's plane along the same ray (so a surface lit at a
// slant does not shadow itself) and p lies behind its own plane (in_front_of).
float patch_blocker_m(vec2 uv, ivec2 size, vec3 p, vec3 p_test, vec3 n, float receiver_m, float bias_m,
                      float texel_m) {
    ivec2 texel = ivec2(uv);
    vec4 occ = texelFetch(rsm_position, texel, 0);
    if (occ.w <= 0.0) {
        return 1e30;
    }
    float d = length(occ.xyz - light_pos_ws);
    bool nearer = d < plane_distance_m(uv, size, p_test, n, receiver_m) - bias_m;
    return nearer && !in_front_of(p, occ, texelFetch(rsm_normal, texel, 0).xyz, texel_m) ? d : -1.0;
}

float patch_visibility(vec2 uv, ivec2 size, vec3 p, vec3 p_test, vec3 n, float bias_m, float texel_m) {
    float receiver_m = length(p_test - light_pos_ws);
    float texel_rad = sqrt(texel_scale);
    vec2 lo = vec2(0.5);
    vec2 hi = vec2(size) - 0.5;
    float centre = patch_blocker_m(clamp(uv, lo, hi), size, p, p_test, n, receiver_m, bias_m, texel_m);
    bool centre_lit = centre < 0.0 || centre >= 1e29;
    // Blockers are searched for as far as those a quarter of the way from the light cast their
    // penumbra: r (4 / z_r - 1 / z_r).
    float search = clamp(3.0 * emitter_radius_m / (receiver_m * texel_rad), 0.5, MAX_SOFT_TEXELS);
    float blockers = 0.0;
    float blocker_sum_m = 0.0;
    for (int i = 0; i < SOFT_TAPS; ++i) {
        float d = patch_blocker_m(clamp(uv + search * vogel(i), lo, hi), size, p, p_test, n, receiver_m, bias_m,
                                  texel_m);
        if (d >= 0.0 && d < 1e29) {
            blockers += 1.0;
            blocker_sum_m += d;
        }
    }
    if (blockers == 0.0) {
        return centre_lit ? 1.0 : 0.0;  // none in the disc: the centre's own test decides
    }
    float mean_blocker_m = blocker_sum_m / blockers;
    float radius = clamp(emitter_radius_m * (1.0 / mean_blocker_m - 1.0 / receiver_m) / texel_rad, 0.5,
                         MAX_SOFT_TEXELS);
    float lit = 0.0;
    for (int i = 0; i < SOFT_TAPS; ++i) {
        float d = patch_blocker_m(clamp(uv + radius * vogel(i), lo, hi), size, p, p_test, n, receiver_m, bias_m,
                                  texel_m);
        // A texel with no geometry counts as the centre does (a disc reaching past a closed room's outer
        // wall must not light its inside).
        bool sample_lit = d >= 1e29 ? centre_lit : d < 0.0;
        lit += sample_lit ? 1.0 : 0.0;
    }
    return lit / float(SOFT_TAPS);
}
#endif

#if !defined(SOFT_SUN) && !defined(POLYGONS)
ivec2 shadow_texel(vec3 q, ivec2 size) {
    vec4 clip = light_view_projection * vec4(q, 1.0);
    return clamp(ivec2((clip.xy / clip.w * 0.5 + 0.5) * vec2(size)), ivec2(0), size - 1);
}

// The hard shadow test of point q: nothing the map stores at q's texel is nearer the light than q.
bool shadow_lit(vec3 q, ivec2 size, float bias_m) {
    vec4 occ = texelFetch(rsm_position, shadow_texel(q, size), 0);
    if (occ.w <= 0.0) {
        return true;
    }
    float receiver = light_kind == LIGHT_SUN ? dot(q, emit_axis) : length(q - light_pos_ws);
    float occluder = light_kind == LIGHT_SUN ? dot(occ.xyz, emit_axis) : length(occ.xyz - light_pos_ws);
    return receiver <= occluder + bias_m;
}

// Whether p lies in front of the plane of the surface at q's texel (nothing there: yes).
bool in_front_of_texel(vec3 p, vec3 q, ivec2 size, float texel_m) {
    ivec2 texel = shadow_texel(q, size);
    vec4 occ = texelFetch(rsm_position, texel, 0);
    return occ.w <= 0.0 || in_front_of(p, occ, texelFetch(rsm_normal, texel, 0).xyz, texel_m);
}
#endif

// This face's direct light (irradiance / pi) at surface point p of normal n: 0 where another face shades
// it, where the light does not reach it, or in its shadow.
vec3 face_light(vec3 p, vec3 n) {
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
    // Shadow test against the RSM's stored positions. The receiver is lifted off its surface by 1.5 RSM
    // texels (normal-offset bias here; along the light's ray in the hard test below) so it does not
    // shadow itself; every bias is in texels, so the result does not depend on the scene's scale.
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
#if defined(SOFT_SUN)
        lit = soft_sun_visibility((ndc.xy * 0.5 + 0.5) * vec2(size), size, dot(p_test, emit_axis), bias_m, texel_m,
                                  n);
#elif defined(POLYGONS)
        lit = patch_visibility((ndc.xy * 0.5 + 0.5) * vec2(size), size, p, p_test, n, bias_m, texel_m);
#else
        // Two lookups. Along the ray: the receiver moved towards the light by the same 1.5 texels of
        // height over the cosine keeps its own texel (no sideways move, so real shadow edges stay put);
        // it is lit if nothing there is nearer the light. That move can cross a surface within a few
        // texels (a zero-thickness wall at its foot, a solid touching another), so where the ray's
        // texel holds a surface the receiver lies behind, the normal offset's test must agree.
        float facing = dot(n, to_light);
        vec3 p_ray = facing > 0.0 ? p + to_light * (1.5 * texel_m / max(facing, 0.1)) : p_test;
        lit = shadow_lit(p_ray, size, bias_m) ? 1.0 : 0.0;
        if (lit > 0.0 && !in_front_of_texel(p, p_ray, size, texel_m)) {
            lit = shadow_lit(p_test, size, bias_m) ? 1.0 : 0.0;
        }
#endif
    }
    return irradiance * (lit / PI);
}

#ifdef AREA_SAMPLES
// A probe atlas texel stands for its whole solid angle, but the G-buffer holds only the surface at its
// centre. Where that surface is seen at a grazing angle its footprint is long, and a bright feature
// thinner than the texel (a sun patch seen from just above the floor) is hit or missed by the centre
// (docs/PROBES.md, "The capture aliases bright light seen at a grazing angle"). There the light is
// the mean over AREA_SAMPLES rays spread across the texel along its footprint
// (probes/footprint.comp.glsl). A ray meets the centre's plane within the distances the texel's two
// neighbours along the footprint see; beyond them it meets what that neighbour sees instead (a wall
// behind the floor), shaded at the neighbour's point; where the neighbour bounds nothing, the
// centre's point. Only the probe atlas's grazing texels run this (their list, passes/direct_light.py);
// the others are shaded at their centres by a program of their own.
vec3 texel_area_light(ivec2 px, vec3 p, vec3 n) {
    vec4 origin = texelFetch(footprint_origin, px, 0);
    vec4 step = texelFetch(footprint_step, px, 0);
    ivec4 neighbours = ivec4(texelFetch(footprint_neighbours, px, 0));
    vec3 o = origin.xyz;
    vec3 w = p - o;
    vec3 a = abs(w);
    vec3 centre = w / max(max(a.x, a.y), a.z);  // forward + s right + t up: its face-axis component is +-1
    float along = dot(w, n);  // the plane's signed distance from the probe, along n
    vec3 sum = vec3(0.0);
    for (int i = 0; i < AREA_SAMPLES; ++i) {
        vec3 d = normalize(centre + step.xyz * ((float(i) + 0.5) / float(AREA_SAMPLES) - 0.5));
        float cos_plane = dot(d, n);
        float t = cos_plane * along > 0.0 ? along / cos_plane : 1e30;  // parallel or away: far
        ivec2 beyond = t < origin.w ? neighbours.xy : (t > step.w ? neighbours.zw : ivec2(0));
        vec3 q = p;
        vec3 nq = n;
        if (t >= origin.w && t <= step.w) {
            q = o + d * t;
        } else if (any(notEqual(beyond, ivec2(0)))) {
            q = texelFetch(gbuf_position, px + beyond, 0).xyz;
            nq = texelFetch(gbuf_normal, px + beyond, 0).xyz;
        }
#if defined(SOFT_SUN) || defined(POLYGONS)
        soft_first = i;
#endif
        sum += face_light(q, nq);
    }
    return sum / float(AREA_SAMPLES);
}
#endif

// Adds this face's light to `direct`, or with accumulate = 0 (a solve's first face on the probe atlas)
// puts it in place of what `direct` holds, so that the atlas needs no zeroing pass before each solve
// (texels that see no geometry are never written: 0 since set-up). One store, after the shading: a
// store on each of its early ways out cost llvmpipe a third more time.
void main() {
    ivec2 px;
    if (!invocation_texel(textureSize(gbuf_position, 0), px)) {
        return;
    }
    vec4 pos = texelFetch(gbuf_position, px, 0);
    if (pos.w == 0.0) {
        return;
    }
    vec3 n = texelFetch(gbuf_normal, px, 0).xyz;
#ifdef AREA_SAMPLES
    vec3 light = texel_area_light(px, pos.xyz, n);
#else
    vec3 light = face_light(pos.xyz, n);
#endif
    if (accumulate != 0 && all(equal(light, vec3(0.0)))) {
        return;
    }
    vec4 acc = accumulate != 0 ? imageLoad(direct, px) : vec4(0.0);
    imageStore(direct, px, acc + vec4(light, 0.0));
}
