// Cone tracing through the radiance pyramid (samplers pyr_px .. pyr_nz, vct/pyramid.glsl's layout).
// Uniforms used: grid_origin, cell_size (m), dims (level 0), levels, tex_width (x size of the
// textures), step_ratio, offset_cells, seed, radiance_scale. Positions `g` are in level-0 cell units.
#include "vct/pyramid.glsl"
#include "common/hash.glsl"

const int MAX_CONE_STEPS = 96;
// Sampled voxels are at most this fraction of the distance travelled: grid-aligned blocks as wide as
// the cone (1.2 t for 6 cones) reach back behind the origin and meet the back of the gatherer's own
// surface, opaque and dark (a closed box of radiance 1 read 0.31 straight up; 0.9 with a cap of 0.25).
// 0.15 rather than 0.25: blocks that straddle a thin wall blend the far room in (the hard-case thin
// wall leaked 1.8 % at 0.25, 0.8 % at 0.15; cornell rel_rmse_8 0.163 against 0.172, gather time x1.4).
// The cone is then sampled narrower than it is wide: an estimate of its mean radiance from its core.
const float SIDE_CAP = 0.15;
#define START_CELLS 0.5
// The level-dithering random numbers' own stream: random01(x, y, hash_u32(stream ^ DITHER_STREAM)).
const uint DITHER_STREAM = 0x68e31da4u;

// Where a position g (level-0 cell units) is sampled at level `level` in every direction's texture
// (they share one layout): clamped to that level's cells (the march stops at the grid's border, so
// clamping only reaches half a cell outside it), then shifted to the level's place along x.
vec3 level_uvw(vec3 g, int level) {
    ivec3 ld = level_dims(dims, level);
    vec3 q = clamp(g / float(1 << level), vec3(0.5), vec3(ld) - 0.5);
    q.x += float(level_offset(dims, level));
    return q / vec3(float(tex_width), float(dims.y), float(dims.z));
}

// What a ray travelling along d meets: the light travelling along -d, from the three axis textures.
// Opacity: a'(d) = 1 - prod_i (1 - a_i)^|d_i|. A layer of coverage a across axis i is crossed over
// 1 / |d_i| cells by a ray along d, so it passes (1 - a) of the light at every angle, as a wall with
// holes does; the d^2-weighted mean of the a_i (Crassin et al.) lets an opaque wall seen at 60 degrees
// pass 37 % and cones leave closed rooms (a closed box of radiance 1 read 0.36 with 6 cones).
// The product is exp2(sum |d_i| log2(1 - a_i)), each log floored at -1e30 so that an opaque layer
// (log -inf) gives 0 and an axis the ray does not cross (|d_i| = 0) gives a factor 1, not NaN.
// Radiance: the d^2-weighted colours over the d^2-weighted opacities (exact for one surface
// orientation: each axis texture holds that surface's radiance times its coverage).
vec4 sample_directional(vec3 g, int level, vec3 d) {
    vec3 uvw = level_uvw(g, level);
    vec4 sx = d.x > 0.0 ? texture(pyr_nx, uvw) : texture(pyr_px, uvw);
    vec4 sy = d.y > 0.0 ? texture(pyr_ny, uvw) : texture(pyr_py, uvw);
    vec4 sz = d.z > 0.0 ? texture(pyr_nz, uvw) : texture(pyr_pz, uvw);
    vec3 a = clamp(vec3(sx.a, sy.a, sz.a), 0.0, 1.0);
    float transmit = exp2(dot(abs(d), max(log2(1.0 - a), vec3(-1e30))));
    vec3 w = d * d;
    float weight = dot(w, a);
    vec3 colour = w.x * sx.rgb + w.y * sy.rgb + w.z * sz.rgb;
    vec3 radiance = weight > 1e-6 ? colour / weight : vec3(0.0);
    float alpha = 1.0 - transmit;
    return vec4(alpha * radiance, alpha);
}

// Front-to-back compositing along one cone from g0 (cell units) in direction d with half-angle tangent
// tan_half: returns (mean radiance over the cone, W/m^2/sr; accumulated opacity). The cone's width
// `side` is its diameter scaled to the same cross-section area (sqrt(pi)/2: a disc of diameter D covers
// pi D^2 / 4), so a voxel of radiance L filling the cone reads L; capped by side_cap x t and by the
// height over the receiver's own surface less a cell (`rise` = d.n): a coarse block that reached down
// to that surface would show a low cone its back side, opaque and dark (corners read 0.3 of Cycles).
// Each step reads one level, floor(log2(side) + dither) (stochastic rounding: level lo or lo + 1 with
// the probabilities of a blend of the two, half the texture fetches of blending them; a 6-cone gather
// at 1080p on an H100: 13 -> 7 ms) and steps by that level's block size s. Opacity accumulates
// linearly, a += a_s dt / s, and each step adds its radiance times the opacity it added. Trilinear
// filtering turns an opaque one-voxel wall into a tent of width 2s whose samples at steps of s sum to 1
// at any phase, so the wall stops the cone; the usual a += (1 - a)(1 - (1 - a_s)^(dt/s)) let 19 %
// through it (tests/gpu/test_vct.py) and 10 % of a closed box's light out. `dither` (uniform in [0, 1))
// stays the same along the cone: steps of one cone keep their level until its width doubles (a wall
// between two samples of different levels could be missed). The pyramid holds radiance x
// radiance_scale (vct_pyramid.radiance_scale: half floats' range); the result is unscaled.
vec4 trace_cone(vec3 g0, vec3 d, float tan_half, float rise, float side_cap, float dither) {
    vec3 colour = vec3(0.0);
    float alpha = 0.0;
    float t = START_CELLS;
    for (int i = 0; i < MAX_CONE_STEPS; i++) {
        vec3 g = g0 + t * d;
        if (any(lessThan(g, vec3(0.0))) || any(greaterThan(g, vec3(dims))) || alpha > 0.995) {
            break;
        }
        float above = offset_cells + t * rise;  // height over the receiver's own surface, cells
        float surface_cap = max(1.0, above - 1.0);
        float side = max(1.0, min(min(0.88622693 * 2.0 * t * tan_half, side_cap * t), surface_cap));
        // Rounded up only where the doubled block still clears the receiver's surface.
        int level = min(int(floor(log2(side) + dither)), levels - 1);
        level = exp2(float(level)) > surface_cap ? max(level - 1, 0) : level;
        vec4 s = sample_directional(g, level, d);
        float next = min(1.0, alpha + s.a * step_ratio);
        vec3 radiance = s.a > 1e-4 ? s.rgb / s.a : vec3(0.0);
        colour += radiance * (next - alpha);
        alpha = next;
        t += step_ratio * exp2(float(level));
    }
    return vec4(colour / radiance_scale, alpha);
}

// Orthonormal tangents of a unit normal (Duff et al. 2017, branchless).
void tangent_frame(vec3 n, out vec3 tx, out vec3 ty) {
    float s = n.z >= 0.0 ? 1.0 : -1.0;
    float a = -1.0 / (s + n.z);
    float b = n.x * n.y * a;
    tx = vec3(1.0 + s * n.x * n.x * a, s * b, -s * n.x);
    ty = vec3(b, s + n.y * n.y * a, -n.y);
}
