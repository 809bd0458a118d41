// Shadow-mapped direct diffuse light of one light face at every G-buffer pixel, added to `direct` (or in
// its place: `accumulate`, main()).
// Output unit: Cycles' Diffuse Direct pass = irradiance / pi (W/m^2/sr per unit albedo).
// Compiled per kind of light (passes/direct_light.py): POLYGONS for a light with its shape, SOFT_SUN for
// a sun with an angle. llvmpipe pays for a branch's code even where no invocation takes it: a spot
// shaded 1.1 M probe atlas texels in ~270 ms with both, ~60 ms without (docs/PROBES.md).
#include "common/light.glsl"
#include "common/texel_list.glsl"
#include "common/polygon.glsl"
#include "common/receiver_plane.glsl"
#include "common/ray_triangle.glsl"

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

// Whether receiver p lies in front of the plane of the surface a shadow-map texel stores (its position
// and its normal, which the RSM turns towards the light), so that surface cannot block p's light: a real
// blocker crosses the segment from the light to p, so p lies behind its plane, while a wall p stands in
// front of (a floor's last pixels looking up the wall beside them) does not, and a zero-thickness wall
// between p and the light still does (p lies behind the side the light sees). The margin, 1 % of a
// texel, absorbs fp32 rounding at a crease. docs/DIRECT.md, "The shadow test".
bool in_front_of(vec3 p, vec4 occ_position, vec3 occ_normal, float texel_m) {
    return dot(p - occ_position.xyz, occ_normal) >= -0.01 * texel_m;
}

#ifndef POLYGONS
// The exact hard shadow. A shadow map's texel holds the surface its centre sees, so a test against the
// texel puts an edge anywhere within it: a window's sunlit patch came out a camera pixel off along its
// edges at 1024 texels, and a 4096-texel map still flipped single pixels. Here the map only says which
// triangles to try: each texel names the triangle it sees (rsm.frag.glsl), and the receiver is lit
// unless the segment from it to the light crosses one of those the 3 x 3 texels around its own name.
// The segment projects into the map at that texel (a sun's map is orthographic along its rays; a
// lamp's is a perspective from its centre), and whatever crosses it first from the light covers that
// point, so the nearest texels see it unless it is thinner than a texel and hidden there behind a
// surface nearer the light (docs/DIRECT.md, "The shadow test").

ivec2 shadow_texel(vec3 q, ivec2 size) {
    vec4 clip = light_view_projection * vec4(q, 1.0);
    return clamp(ivec2((clip.xy / clip.w * 0.5 + 0.5) * vec2(size)), ivec2(0), size - 1);
}

vec3 occluder_corner(int t, int k) {
    return texelFetch(occluders, ivec2(3 * (t % OCCLUDER_ROW) + k, t / OCCLUDER_ROW), 0).xyz;
}

// Whether q + s w crosses triangle t (either side) for s_min < s < s_max.
bool segment_crosses(int t, vec3 q, vec3 w, float s_min, float s_max) {
    return ray_crosses_triangle(occluder_corner(t, 0), occluder_corner(t, 1), occluder_corner(t, 2), q, w, s_min,
                                s_max);
}

// How far x lies from the light along its rays: a sun's depth along them, a lamp's distance.
float light_depth(vec3 x) {
    return light_kind == LIGHT_SUN ? dot(x, emit_axis) : length(x - light_pos_ws);
}

// 0 where a triangle the map names in the 3 x 3 texels around `centre` crosses the segment from q along
// w (s_min < s < s_max); else 0 where all 9 texels hold a surface that blocks q (nearer the light, q
// behind its plane: in_front_of), else 1. The second rule is for a gap narrower than a texel in a
// blocker nearer the light: no texel sees through it, so the map names nothing behind it, though what
// is behind may cover q (Sponza's balustrades under its arches, seen from the sphere lamp's 256-texel
// map, lit a gallery floor). At a real edge some texel around q sees past the blocker.
float exact_visibility(ivec2 centre, vec3 q, vec3 w, float s_min, float s_max, ivec2 size, float texel_m) {
    float q_depth = light_depth(q);
    bool all_block = true;
    int last = -1;  // neighbouring texels mostly see one triangle: each run of it is tried once
    for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
            ivec2 texel = clamp(centre + ivec2(dx, dy), ivec2(0), size - 1);
            int t = int(texelFetch(rsm_flux, texel, 0).w) - 1;
            if (t >= 0 && t != last && segment_crosses(t, q, w, s_min, s_max)) {
                return 0.0;
            }
            last = t;
            if (all_block) {
                vec4 occ = texelFetch(rsm_position, texel, 0);
                all_block = occ.w > 0.0 && light_depth(occ.xyz) < q_depth
                    && !in_front_of(q, occ, texelFetch(rsm_normal, texel, 0).xyz, texel_m);
            }
        }
    }
    return all_block ? 0.0 : 1.0;
}
#endif

#ifdef SOFT_SUN
// A sun of angular diameter 2 atan(sun_tan_half) casts a penumbra (receiver depth - blocker depth) x
// sun_tan_half wide on each side. A world region (world.py) is such a sun, as wide as its share of the sky.

float sun_depth(vec2 uv, ivec2 size) {
    vec4 occ = texelFetch(rsm_position, clamp(ivec2(uv), ivec2(0), size - 1), 0);
    return occ.w > 0.0 ? dot(occ.xyz, emit_axis) : 1e30;  // no geometry: nothing blocks
}

// The sun's visible share of its disc from receiver p (depth `receiver` at map position uv; q: p lifted
// for the exact test). Blockers are searched for in a disc as wide as the widest penumbra; with none,
// p sees the whole sun.
float soft_sun_visibility(vec2 uv, ivec2 size, float receiver, float bias_m, float texel_m, vec3 n, vec3 q) {
    // The map's rows: a world vector's offset in NDC.
    vec3 row_x = vec3(light_view_projection[0][0], light_view_projection[1][0], light_view_projection[2][0]);
    vec3 row_y = vec3(light_view_projection[0][1], light_view_projection[1][1], light_view_projection[2][1]);
    vec2 slope = receiver_depth_per_texel(n, row_x, row_y, 0.5 * vec2(size), emit_axis);
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
    // Each tap is a ray to a point of the sun's disc (uniform over it: the Vogel spiral), tested exactly:
    // around where it passes the blockers' mean depth (the texel the classic filter reads), then against
    // the triangles the map names along its path across the map, from the receiver's texel outwards half
    // a texel at a time, as far as the blocker search reached.
    float ahead_m = max(receiver - depth_sum / blockers, 0.0);
    vec3 axis_x = normalize(row_x);
    vec3 axis_y = normalize(row_y);
    float s_min = exact_near_texels * texel_m;
    float lit = 0.0;
    for (int i = 0; i < SOFT_TAPS; ++i) {
        vec2 v = vogel(i);
        vec3 d = -emit_axis + sun_tan_half * (v.x * axis_x + v.y * axis_y);  // 1 along the sun per metre
        vec3 w = normalize(d);
        float tap_lit = exact_visibility(shadow_texel(q + ahead_m * d, size), q, w, s_min, 1e30, size, texel_m);
        float step_m = 0.5 * texel_m / max(length(v) * sun_tan_half, 1e-9);  // half a texel sideways
        int steps = int(ceil(2.0 * search * length(v)));
        int last = -1;
        for (int k = 0; k <= steps && tap_lit > 0.0; ++k) {
            int t = int(texelFetch(rsm_flux, shadow_texel(q + float(k) * step_m * d, size), 0).w) - 1;
            if (t >= 0 && t != last && segment_crosses(t, q, w, s_min, 1e30)) {
                tap_lit = 0.0;
            }
            last = t;
        }
        lit += tap_lit;
    }
    return lit / float(SOFT_TAPS);
}
#endif


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
    // texels (normal-offset bias; the exact hard test below lifts it far less) so it does not shadow
    // itself; every bias is in texels, so the result does not depend on the scene's scale.
    vec3 p_test = p + n * (1.5 * texel_m);
    float bias_m = shadow_bias_texels * texel_m;
#if !defined(SOFT_SUN) && !defined(POLYGONS)
    // The exact test's segment starts a little off the receiver's surface instead (EXACT_LIFT_TEXELS:
    // fp32's rounding of where the G-buffer put it, plus the user's shadow bias), so its own triangle
    // lies behind it. Its whole length projects to one point of the map, in the face its start lies in.
    p_test = p + n * ((EXACT_LIFT_TEXELS + shadow_bias_texels) * texel_m);
#endif
    // Another face of this point light shades this pixel: the one its lifted point projects into. The
    // faces of one light may differ in texels (light_views.view_texels), and so in lift: each face
    // asking where its own lift lands would leave a pixel on the edge between a fine and a coarse face to
    // neither or to both (a band 2-5 % dark across cornell-large-area's walls). So every face asks where
    // the lift of a full-resolution face lands (face_lift_share: its texels / the light's most); its
    // shadow test below keeps its own lift, clamped into its map. (A sun has one view, no faces.)
#ifndef SOFT_SUN
    // (at share 1, p_test itself: p + (p_test - p) need not round back to it)
    vec3 p_face = face_lift_share == 1.0 ? p_test : p + (p_test - p) * face_lift_share;
    if (face_index >= 0 && cube_face(p_face - light_pos_ws) != face_index) {
        return vec3(0.0);
    }
#endif
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
    if (face_index >= 0) {
        ndc.xy = clamp(ndc.xy, -1.0, 1.0);  // a coarse face's larger lift may carry p_test past its edge
    }
    float lit = 1.0;
    if (clip.w > 0.0 && all(lessThanEqual(abs(ndc.xy), vec2(1.0)))) {
        ivec2 size = textureSize(rsm_position, 0);
#if defined(SOFT_SUN)
        lit = soft_sun_visibility((ndc.xy * 0.5 + 0.5) * vec2(size), size, dot(p_test, emit_axis), bias_m, texel_m,
                                  n, p + n * ((EXACT_LIFT_TEXELS + shadow_bias_texels) * texel_m));
#elif defined(POLYGONS)
        lit = patch_visibility((ndc.xy * 0.5 + 0.5) * vec2(size), size, p, p_test, n, bias_m, texel_m);
#else
        float reach = light_kind == LIGHT_SUN ? 1e30 : length(light_pos_ws - p_test);
        vec3 w = light_kind == LIGHT_SUN ? to_light : (light_pos_ws - p_test) / reach;
        lit = exact_visibility(shadow_texel(p_test, size), p_test, w, exact_near_texels * texel_m, reach, size,
                               texel_m);
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
