// The sky's direct diffuse light at every G-buffer pixel in one pass: a loop over the sky directions
// (world.py's regions of the world map, each along its vector irradiance), each shadowed by its tile of
// the sky atlas. Added to `direct` (or, with accumulate = 0, replacing it), in Cycles' Diffuse Direct unit:
// irradiance / pi.
//
// sky_table, one row per direction: texels 0-3 the rows of its orthographic view-projection, texel 4
// (axis the light travels along, texel size in m), texel 5 (irradiance normal to it, W/m^2 per colour;
// w: the tangent of the region's angular radius, its shadows' penumbra); with SKY_RAYS, texels 6 on the
// region's `sky_rays` rays (xyz towards the sky, w: the share of the region's light each stands for;
// world.region_taps).
//
// Compiled two ways (passes/sky_light.py): the shadow maps' percentage-closer soft shadows (the
// viewport's), or with SKY_RAYS each region's rays tested exactly against the triangles wherever the
// depth bounds do not show the receiver in front of everything (renders and bakes that ask for it,
// RsmConfig.sky_rays; docs/DIRECT.md, "Exact rays").
#include "common/texel_list.glsl"
#include "common/receiver_plane.glsl"
#ifdef SKY_RAYS
#include "common/bvh.glsl"

// The share of direction k's region that receiver p (normal n) sees: its rays, each tested exactly
// against the triangles (common/bvh.glsl), weighted by the share of the light each stands for; they start
// off the surface and skip near crossings as the direct pass's exact shadows do (common/ray_triangle.glsl),
// in texels of the direction's tile.
// `hint`: the triangle the last blocked ray crossed (bvh_occluded), carried from region to region.
float ray_share(int k, vec3 p, vec3 n, float texel_m, inout int hint) {
    vec3 q = p + n * (EXACT_LIFT_TEXELS * texel_m);
    float lit = 0.0;
    for (int j = 0; j < sky_rays; ++j) {
        vec4 ray = texelFetch(sky_table, ivec2(6 + j, k), 0);
        if (ray.w > 0.0 && !bvh_occluded(q, ray.xyz, exact_near_texels * texel_m, 1e30, hint)) {
            lit += ray.w;
        }
    }
    return lit;
}
#endif

const float PI = 3.14159265;
// The receiver is lifted half a texel along its normal, for its own texel's depth, and each tap is
// compared with the receiver's own plane where the plane rises towards the direction there
// (common/receiver_plane.glsl), so that a surface lit at a slant does not shadow itself across a wide region's disc.
// The plane counts at most PLANE_MAX_TEXELS texels of depth: extrapolated further, a grazing direction's
// disc reached past a closed box's roof (tests/gpu/test_sky.py; 16 texels let its 0.4 m walls through,
// 1-4 shadowed an open floor under 16 directions by more than 1.5 %). Without the plane, a lift that
// grew with the region's width (0.75 texels + 2 per unit of tan(half-angle), at most 1.5) moved the
// lookup sideways, through a window's edge. Direct rel_rmse_8 / bias at 128 px, that lift -> this:
// window-sky 0.094 / 1.004 -> 0.080 / 1.009, window-sky-sun 0.036 / 1.001 -> 0.030 / 1.001,
// cornell-grey-world 0.028 -> 0.027.
const float LIFT_TEXELS = 0.5;
const float PLANE_MAX_TEXELS = 8.0;
// Taps per direction: few, since the sum over a hundred directions, each turned differently, is what
// samples the penumbra (4 + 8 taps: window-sky direct rel_rmse_8 0.207; 16 + 16: 0.203).
const int SEARCH_TAPS = 4;
const int FILTER_TAPS = 8;
const float MAX_SOFT_TEXELS = float(BLOCK);  // the widest penumbra searched and filtered, in texels

// Tap i of n on a Vogel spiral filling the unit disc.
vec2 tap(int i, int n) {
    float r = sqrt((float(i) + 0.5) / float(n));
    float a = float(i) * 2.39996323;
    return r * vec2(cos(a), sin(a));
}

// Depth along the axis of atlas texel `t` of tile `tile0` (clamped to the tile); none: +inf.
float sky_depth(ivec2 tile0, ivec2 t) {
    vec4 d = texelFetch(sky_depth_atlas, tile0 + clamp(t, ivec2(0), ivec2(tile_texels - 1)), 0);
    return d.w > 0.0 ? d.x : 1e30;
}

void main() {
    ivec2 px;
    if (!invocation_texel(textureSize(gbuf_position, 0), px)) {
        return;
    }
    vec4 pos = texelFetch(gbuf_position, px, 0);
    if (pos.w == 0.0) {
        return;
    }
    vec3 p = pos.xyz;
    vec3 n = texelFetch(gbuf_normal, px, 0).xyz;
    vec3 sum = vec3(0.0);
#ifdef SKY_RAYS
    int hint = -1;
#endif
    for (int k = sky_first; k < min(sky_first + sky_chunk, sky_count); ++k) {
        vec4 axis_texel = texelFetch(sky_table, ivec2(4, k), 0);
        float cos_n = -dot(n, axis_texel.xyz);
        if (cos_n <= 0.0) {
            continue;  // the direction lies below this surface's horizon
        }
        vec4 light_texel = texelFetch(sky_table, ivec2(5, k), 0);
        float tan_half = light_texel.w;
        vec4 p_test = vec4(p + n * (LIFT_TEXELS * axis_texel.w), 1.0);
        vec4 row_x = texelFetch(sky_table, ivec2(0, k), 0);
        vec4 row_y = texelFetch(sky_table, ivec2(1, k), 0);
        vec2 ndc = vec2(dot(row_x, p_test), dot(row_y, p_test));
        float receiver = dot(p_test.xyz, axis_texel.xyz);
        vec2 slope = receiver_depth_per_texel(n, row_x.xyz, row_y.xyz, vec2(0.5 * float(tile_texels)), axis_texel.xyz);
        float plane_floor = -PLANE_MAX_TEXELS * axis_texel.w;
        // Soft shadow (percentage-closer soft shadows, as a wide sun's in the direct pass): the region is
        // a cone of half-angle atan(tan_half); blockers found in a disc of the widest penumbra give its
        // width (receiver - blocker depth) x tan_half, and the lit share of a disc that wide is the
        // visibility. Few taps per direction, their pattern turned by a different angle per direction,
        // so that summed over many directions they sample the disc densely.
        vec2 uv = (ndc * 0.5 + 0.5) * float(tile_texels);
        ivec2 tile0 = ivec2(k % tiles_x, k / tiles_x) * tile_texels;
        float turn = float(k) * 2.39996323;
        mat2 rot = mat2(cos(turn), sin(turn), -sin(turn), cos(turn));
        // The depth bounds of the disc's 3 x 3 blocks (bounds.comp.glsl) settle most directions in one
        // fetch, with the answer the taps would give: the receiver in front of everything there is lit,
        // behind everything blocked (from inside a room, most of the sky).
        float texel_m = axis_texel.w;
        float search = min(MAX_SOFT_TEXELS, tan_half * scene_diagonal_m / texel_m);
        ivec2 block = clamp(ivec2(uv), ivec2(0), ivec2(tile_texels - 1)) / BLOCK + tile0 / BLOCK;
        vec2 bounds = texelFetch(sky_bounds, block, 0).xy;
        if (receiver <= bounds.x) {
            sum += light_texel.rgb * cos_n;
            continue;
        }
#ifdef SKY_RAYS
        // Behind everything there does not settle a region for its rays: rays slanted across it escape
        // beside what stands over the receiver (taken as blocked, window-sky read 0.065 / 0.964 against
        // 0.028 / 0.996); nor does the filter below, either way (0.043 trusting its fully lit, 0.056 its
        // fully blocked).
        sum += light_texel.rgb * (cos_n * ray_share(k, p, n, texel_m, hint));
#else
        if (receiver > bounds.y) {
            continue;
        }
        // The blocker nearest the receiver sizes the penumbra (the centre's own texel included): a wall
        // the receiver stands behind hardens it to half a texel. The mean blocker depth, as PCSS has it,
        // let far blockers widen the disc until it reached past a closed box's walls at grazing
        // directions (a closed box under a sky: 2 % of the sky's light along its inner edges).
        float centre = sky_depth(tile0, ivec2(uv));
        float nearest = centre < receiver ? centre : -1e30;
        for (int i = 0; i < SEARCH_TAPS; ++i) {
            vec2 offset = search * (rot * tap(i, SEARCH_TAPS));
            float d = sky_depth(tile0, ivec2(uv + offset));
            if (d < receiver + clamp(dot(slope, offset), plane_floor, 0.0)) {
                nearest = max(nearest, d);
            }
        }
        float lit = 1.0;
        if (nearest > -1e30) {
            // A texel with no geometry lies outside everything the direction sees: taken as lit, it lets
            // a disc reaching past a closed room's outer walls light the room's inside; it counts as the
            // centre does.
            float centre_lit = centre >= receiver ? 1.0 : 0.0;
            float radius = clamp((receiver - nearest) * tan_half / texel_m, 0.5, MAX_SOFT_TEXELS);
            lit = 0.0;
            for (int i = 0; i < FILTER_TAPS; ++i) {
                vec2 offset = radius * (rot * tap(i, FILTER_TAPS));
                float d = sky_depth(tile0, ivec2(uv + offset));
                float plane = receiver + clamp(dot(slope, offset), plane_floor, 0.0);
                lit += d >= 1e29 ? centre_lit : (d >= plane ? 1.0 : 0.0);
            }
            lit /= float(FILTER_TAPS);
        }
        sum += light_texel.rgb * (cos_n * lit);
#endif
    }
    vec4 acc = accumulate != 0 ? imageLoad(direct, px) : vec4(0.0);
    imageStore(direct, px, acc + vec4(sum / PI, 0.0));
}
