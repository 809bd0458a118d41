// RSM indirect gather (Dachsbacher & Stamminger 2005), no visibility: every pixel sums the light of
// VPLs drawn from one RSM face, added to `indirect` in Cycles' Diffuse Indirect unit (E / pi).
//
// Sampling: the RSM is split into strata_per_side^2 equal blocks; each pixel draws one texel per block
// (its own hash, so the estimate is unbiased and the noise is per-pixel, not structured) weighted by
// the block's texel count (refinement gathers step along a sequence, below). One dispatch handles
// block rows [row_begin, row_end): llvmpipe silently stops a shader after 65,535 loop iterations, so
// the caller splits long visibility marches. A VPL of flux phi is a Lambertian disk of area A:
//     E += phi / pi * cos_vpl * cos_x / (r^2 + A / pi)
// The A / pi term is the on-axis form factor of a disk: it keeps nearby VPLs from spiking. A drawn VPL
// stands for its whole block (`weight` texels), so its disk is taken as DISK_SHARE of the block's area,
// A = DISK_SHARE x weight x surfel area: a VPL within a few centimetres of the receiver no longer spikes
// by the block's weight (at 256 VPLs 88 % of the squared difference between two seeds sat in 1 % of
// the pixels, next to the walls). Cornell 128 px, 256 VPLs, the two geometric denoise iterations
// (tools/noise_table.py; noise / rel_rmse_8 / bias): share 1 / 256 (the surfel alone) 0.059 / 0.193 /
// 1.14; 1 / 16 0.041 / 0.195; 1 / 4 0.034 / 0.201 / 1.13; 1 (the block) 0.023 / 0.221 (the corners' real
// near-field light lost). The bake of the Cornell floor (tests/e2e/test_bake_vs_cycles.py: 1024 VPLs,
// 64 x 64 texels, the first row 4 cm from the walls) bounds it: rel_rmse_8 / bias 0.126 / 0.948 at
// 1 / 256, 0.149 / 0.931 at 1 / 16, 0.208 / 0.900 at 1 / 4 (bound 0.18, bias within 0.08).
//
// Near draws (multiple importance sampling). A receiver's brightest VPLs are its near ones, and in a
// large RSM they are few: under Sponza's sun a shaded gallery floor gets most of its light from the
// lit courtyard floor a metre or two away, a few texels of a 256^2 map that its one draw per 16^2
// block rarely meets (88 % of the squared difference between two seeds sat in 1 % of the pixels).
// Points near the receiver in the world project near its own texel c in the light's view, so besides
// the strata each pixel draws near_strata^2 texels in each of three squares centred at c (sides
// in NEAR_SIDE_BLOCKS), one per cell of a near_strata^2 split of the square: stratified as the blocks
// are, for without it a smooth near field (a wall's crease) grew noisier, the squares' random draws
// replacing part of the strata's. Every draw, of either kind, is weighted by the
// balance heuristic over the expected draws per texel: 1 / (1 / weight + near_density(t)), where
// 1 / weight is the strata's (each texel lies in one block and is drawn with probability 1 / weight)
// and near_density(t) the squares' (near_strata^2 / side^2 in each square holding t). Its expectation is
// the sum over every texel of its light, whatever the densities: unbiased, with the integrand
// unchanged (the disk keeps the block's share), so only the noise moves.
// With VOXEL_VISIBILITY, each VPL counts only if the segment between the receiver and the VPL, both
// moved `offset_cells` off their surfaces along their normals, crosses no occupied voxel (a march in
// half-cell steps through the voxelizer's occupancy).

#include "common/hash.glsl"

const float PI = 3.14159265;
const float DISK_SHARE = 0.0625;  // 1 / 16
// The near squares' sides in blocks: a quarter block, a block, four blocks (below).
const vec3 NEAR_SIDE_BLOCKS = vec3(0.25, 1.0, 4.0);

#ifdef VOXEL_VISIBILITY
// 1 if no occupied voxel lies on the segment, skipping its first and last cell: a VPL low on a wall
// sits within a cell of the floor's voxels, which would otherwise hide it from the floor it lights.
float visible(vec3 from_ws, vec3 to_ws) {
    vec3 a = (from_ws - grid_origin) / cell_size;
    vec3 b = (to_ws - grid_origin) / cell_size;
    float len = length(b - a);
    int steps = int(ceil(len * 2.0));
    for (int s = 2; s < steps - 1; ++s) {
        ivec3 c = ivec3(floor(mix(a, b, float(s) / float(steps))));
        if (all(greaterThanEqual(c, ivec3(0))) && all(lessThan(c, grid_dims))
            && texelFetch(occupancy, c, 0).a > 0.5) {
            return 0.0;
        }
    }
    return 1.0;
}
#endif

// The light of the VPL at RSM texel t on receiver x (normal n), unweighted (E, W/m^2 per texel drawn).
vec3 vpl_light(ivec2 t, vec3 x, vec3 n, float disk_share) {
    vec4 vpl_pos = texelFetch(rsm_position, t, 0);
    if (vpl_pos.w == 0.0) {
        return vec3(0.0);
    }
    vec4 vpl_normal = texelFetch(rsm_normal, t, 0);
    vec3 d = vpl_pos.xyz - x;
    float r2 = dot(d, d);
    vec3 w = d * inversesqrt(max(r2, 1e-20));
    float cos_x = dot(n, w);
    float cos_vpl = -dot(vpl_normal.xyz, w);
    if (cos_x <= 0.0 || cos_vpl <= 0.0) {
        return vec3(0.0);
    }
    float disk_m2 = disk_share * vpl_normal.w;
#ifdef VOXEL_VISIBILITY
    float offset_m = offset_cells * cell_size;
    if (visible(x + n * offset_m, vpl_pos.xyz + vpl_normal.xyz * offset_m) == 0.0) {
        return vec3(0.0);
    }
#endif
    return texelFetch(rsm_flux, t, 0).rgb * (cos_x * cos_vpl / (PI * (r2 + disk_m2 / PI)));
}

// The near squares' expected draws at texel t: `densities` (draws per texel) summed over the squares
// of `sides` texels centred at `centre` that hold t. One unsigned compare per axis and square: t lies
// in a square of side s iff 0 <= t - (centre - s / 2) < s.
float near_density(ivec2 t, ivec2 centre, ivec3 sides, vec3 densities) {
    ivec2 d = t - centre;
    bvec3 inside = bvec3(all(lessThan(uvec2(d + sides.x / 2), uvec2(sides.x))),
                         all(lessThan(uvec2(d + sides.y / 2), uvec2(sides.y))),
                         all(lessThan(uvec2(d + sides.z / 2), uvec2(sides.z))));
    return dot(vec3(inside), densities);
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
    vec3 x = pos.xyz;
    vec3 n = texelFetch(gbuf_normal, px, 0).xyz;
    ivec2 rsm_size = textureSize(rsm_flux, 0);
    vec2 block = vec2(rsm_size) / float(strata_per_side);
    float weight = block.x * block.y;
    float disk_share = DISK_SHARE * weight;
    uint pixel_id = uint(px.y * 65536 + px.x);
    // The receiver's own texel. No near draws where it lies behind the light's view (a cube face's
    // back) or far off the map (where the texel would overflow an int): a choice per pixel, so the
    // densities stay those of the draws made.
    vec4 clip = rsm_view_projection * vec4(x, 1.0);
    vec2 ndc = clip.xy / max(clip.w, 1e-20);
    bool near = near_strata > 0 && clip.w > 0.0 && all(lessThan(abs(ndc), vec2(16.0)));
    ivec2 centre = ivec2(floor((clamp(ndc, -16.0, 16.0) * 0.5 + 0.5) * vec2(rsm_size)));
    // RSM faces are square: block.x is the block's side.
    ivec3 sides = max(ivec3(block.x * NEAR_SIDE_BLOCKS + 0.5), ivec3(1));
    int near_draws = near_strata * near_strata;
    // No near draws: no near density either, so every draw keeps the strata's weight alone.
    vec3 densities = near ? float(near_draws) / vec3(sides * sides) : vec3(0.0);
    float strata_density = 1.0 / weight;
    // Progressive refinement: the n-th gather (sample_index) keeps the update's draws and moves each
    // by n x the R2 sequence's steps (Roberts 2018), so a pixel's draws in a block over the samples form
    // one low-discrepancy set (each still uniform in the block: unbiased). Cornell 128 px, 16 samples:
    // noise 0.012 with a fresh seed per sample, 0.0058 so.
    vec2 sample_step = float(sample_index) * vec2(0.75487767, 0.56984029);
    vec3 irradiance = vec3(0.0);
    for (int j = row_begin; j < row_end; ++j) {
        for (int i = 0; i < strata_per_side; ++i) {
            uint stratum = uint(j * strata_per_side + i);
            vec2 u = fract(vec2(random01(pixel_id, stratum, uint(seed) * 2u),
                                random01(pixel_id, stratum, uint(seed) * 2u + 1u)) + sample_step);
            ivec2 t = min(ivec2((vec2(i, j) + u) * block), rsm_size - 1);
            irradiance += vpl_light(t, x, n, disk_share) / (strata_density + near_density(t, centre, sides, densities));
        }
    }
    // The near draws, once per pixel: in the dispatch of the first block row.
    if (near && row_begin == 0) {
        for (int k = 0; k < 3; ++k) {
            int side = sides[k];
            vec2 cell = vec2(float(side) / float(near_strata));
            for (int s = 0; s < near_draws; ++s) {
                uint draw = uint(strata_per_side * strata_per_side + k * near_draws + s);
                vec2 u = fract(vec2(random01(pixel_id, draw, uint(seed) * 2u),
                                    random01(pixel_id, draw, uint(seed) * 2u + 1u)) + sample_step);
                vec2 within = (vec2(s % near_strata, s / near_strata) + u) * cell;
                ivec2 t = centre - side / 2 + min(ivec2(within), ivec2(side - 1));
                if (any(lessThan(t, ivec2(0))) || any(greaterThanEqual(t, rsm_size))) {
                    continue;  // off the map: no light there, and its density counted all the same
                }
                irradiance += vpl_light(t, x, n, disk_share) / (strata_density + near_density(t, centre, sides, densities));
            }
        }
    }
    vec4 acc = imageLoad(indirect, px);
    imageStore(indirect, px, acc + vec4(irradiance / PI, 0.0));
}
