// RSM indirect gather (Dachsbacher & Stamminger 2005), no visibility: every pixel sums the light of
// VPLs drawn from one RSM face, added to `indirect` in Cycles' Diffuse Indirect unit (E / pi).
//
// Sampling: the RSM is split into strata_per_side^2 = k^2 blocks; each pixel makes k^2 strata draws,
// each in a block picked with the probability block_pdf gives it and then uniformly within the block,
// weighted by 1 / (expected draws per texel). A draw's random numbers are the image's for that draw plus
// the pixel pattern (common/pixel_pattern.glsl), which steps along a sequence in refinement gathers:
// uniform at each pixel, so its estimate is unbiased, and spread over the pixels the filter averages.
// block_pdf is the blocks' view importance (rsm/importance*.comp.glsl): the mean over receivers spread across the
// G-buffer of the share of each one's light the block holds, half of it uniform; uniform, it is one
// draw per block. Under Sponza's sun 7 % of the map's texels can light anything the camera sees (the
// rest is roof facing the sky), so uniform draws mostly miss. One dispatch handles draws
// [row_begin k, row_end k): llvmpipe silently stops a shader after 65,535 loop iterations, so the
// caller splits long visibility marches. A VPL of flux phi is a Lambertian disk of area A:
//     E += phi / pi * cos_vpl * cos_x / (r^2 + A / pi)
// The A / pi term is the on-axis form factor of a disk: it keeps nearby VPLs from spiking. A drawn VPL
// stands for a block of `weight` texels at one draw per block, so its disk is taken as DISK_SHARE of
// that area, A = DISK_SHARE x weight x surfel area: a VPL within a few centimetres of the receiver no
// longer spikes by the block's weight (at 256 VPLs 88 % of the squared difference between two seeds sat in 1 % of
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
// balance heuristic over the expected draws per texel: 1 / (strata_density(t) + near_density(t)), the
// strata's k^2 block_pdf / (the block's texels) and the squares' (near_strata^2 / side^2 in each square
// holding t). Its expectation is
// the sum over every texel of its light, whatever the densities: unbiased, with the integrand
// unchanged (the disk keeps the block's share), so only the noise moves.
// With VOXEL_VISIBILITY, each VPL counts only if the segment between the receiver and the VPL, both
// moved `offset_cells` off their surfaces along their normals, crosses no occupied voxel (a march in
// half-cell steps through the voxelizer's occupancy).

#include "common/hash.glsl"
#include "common/pixel_pattern.glsl"
#include "rsm/vpl.glsl"

// The hash's first key for the image's random numbers (each draw's, shared by every pixel).
const uint IMAGE_ID = 0xffffffffu;

// The near squares' sides in blocks: a quarter block, a block, four blocks (below).
const vec3 NEAR_SIDE_BLOCKS = vec3(0.25, 1.0, 4.0);

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

// Block i's texels along each axis are [block_lo(i), block_lo(i + 1)): whole texels, so a texel lies in
// exactly one block even where the map's side is not a multiple of strata_per_side. Float arithmetic,
// exact here (integers below 2^24, a quotient that is an integer comes out exact, any other lies at
// least 1 / strata_per_side from one): llvmpipe runs integer division one lane at a time.
ivec2 block_lo(ivec2 i, ivec2 rsm_size) {
    return ivec2(floor(vec2(i * rsm_size) / float(strata_per_side)));
}

// The block holding texel t: the last i with block_lo(i) <= t, i.e. floor(((t + 1) k - 1) / size).
ivec2 block_of(ivec2 t, ivec2 rsm_size) {
    return ivec2(floor(vec2((t + 1) * strata_per_side - 1) / vec2(rsm_size)));
}

// The strata's expected draws at texel t. Guided: strata_per_side^2 draws, each in block i with
// probability block_pdf(i).x, uniform within the block. Else one draw per block of `weight` texels.
float strata_density(ivec2 t, ivec2 rsm_size, bool guided, float weight) {
    if (!guided) {
        return 1.0 / weight;
    }
    ivec2 i = block_of(t, rsm_size);
    ivec2 texels = block_lo(i + 1, rsm_size) - block_lo(i, rsm_size);
    float pdf = texelFetch(block_pdf, i, 0).x;
    return float(strata_per_side * strata_per_side) * pdf / float(texels.x * texels.y);
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
    // Every pixel makes image_sets sets of draws (GIConfig.sample_budget_px: a small image, whose filter has
    // few pixels to average, spends the draws a larger one would), and pixels whose denoise filter finds
    // little of their surface around them (passes/surface_support.py) draw_sets times that. One set per
    // dispatch set (draw_set), each weighing 1 / sets and shifted a further 1 / sets of the way within
    // each draw's cell (the sets stay stratified); a pixel leaves the dispatches beyond its sets at once.
    int sets = image_sets;
    if (draw_sets > 1 && texelFetch(support, px, 0).x < support_threshold) {
        sets *= draw_sets;
    }
    if (draw_set >= sets) {
        return;
    }
    float set_weight = 1.0 / float(sets);
    float set_shift = float(draw_set) / float(sets);
    vec3 x = pos.xyz;
    vec3 n = texelFetch(gbuf_normal, px, 0).xyz;
    ivec2 rsm_size = textureSize(rsm_flux, 0);
    vec2 block = vec2(rsm_size) / float(strata_per_side);
    float weight = block.x * block.y;
    float disk_share = DISK_SHARE * weight;
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
    // The pixel's offsets to the image's random numbers: the pattern, whose n-th refinement gather
    // (sample_index) steps each pixel's draws along a sequence of their own (each still drawn with the
    // same densities: unbiased), and the draw set's shift. Cornell 128 px, 16 samples: noise 0.012 with
    // a fresh seed per sample, 0.0058 with the per-pixel hash stepped along R2 that preceded the pattern.
    vec3 offset = pixel_pattern(px, sample_index) + set_shift;
    // The strata, draws [row_begin k, row_end k) of k^2. Unguided (block_pdf.y = 0, the same in every
    // block): draw s = j k + i takes a texel uniformly in block (i, j). Guided: draw s picks its block by
    // inverting block_pdf's running sum at (s + v) / k^2, one draw per interval of equal probability,
    // then a texel uniformly in the block; the walk over the blocks restarts in each dispatch (at most
    // k^2 steps besides its draws) and computes a block's texels only when it moves.
    bool guided = texelFetch(block_pdf, ivec2(0), 0).y > 0.5;
    int blocks = strata_per_side * strata_per_side;
    vec3 irradiance = vec3(0.0);
    if (guided) {
        int b = 0;
        ivec2 i = ivec2(0);  // block b's column and row, stepped with it (no integer division)
        float pdf = texelFetch(block_pdf, i, 0).x;
        float cdf_end = pdf;
        ivec2 lo = block_lo(i, rsm_size);
        ivec2 texels = block_lo(i + 1, rsm_size) - lo;
        for (int s = row_begin * strata_per_side; s < row_end * strata_per_side; ++s) {
            uint stratum = uint(s);
            float v = fract(random01(IMAGE_ID, stratum + 0x40000000u, uint(seed)) + offset.z);
            float u = (float(s) + v) / float(blocks);
            if (cdf_end <= u) {
                while (cdf_end <= u && b < blocks - 1) {
                    ++b;
                    i = i.x + 1 < strata_per_side ? ivec2(i.x + 1, i.y) : ivec2(0, i.y + 1);
                    pdf = texelFetch(block_pdf, i, 0).x;
                    cdf_end += pdf;
                }
                lo = block_lo(i, rsm_size);
                texels = block_lo(i + 1, rsm_size) - lo;
            }
            if (any(equal(texels, ivec2(0)))) {
                continue;  // a map of fewer texels than blocks a side: this block holds none
            }
            vec2 w = fract(vec2(random01(IMAGE_ID, stratum, uint(seed) * 2u),
                                random01(IMAGE_ID, stratum, uint(seed) * 2u + 1u)) + offset.xy);
            ivec2 t = lo + min(ivec2(w * vec2(texels)), texels - 1);
            // strata_density(t) without its look-ups: t lies in block i, drawn with probability pdf.
            float density = float(blocks) * pdf / float(texels.x * texels.y);
            irradiance += vpl_light(t, x, n, disk_share) / (density + near_density(t, centre, sides, densities));
        }
    } else {
        for (int j = row_begin; j < row_end; ++j) {
            for (int i = 0; i < strata_per_side; ++i) {
                uint stratum = uint(j * strata_per_side + i);
                vec2 w = fract(vec2(random01(IMAGE_ID, stratum, uint(seed) * 2u),
                                    random01(IMAGE_ID, stratum, uint(seed) * 2u + 1u)) + offset.xy);
                ivec2 t = min(ivec2((vec2(i, j) + w) * block), rsm_size - 1);
                float density = 1.0 / weight + near_density(t, centre, sides, densities);
                irradiance += vpl_light(t, x, n, disk_share) / density;
            }
        }
    }
    // The near draws, once per pixel: in the dispatch of the first block row.
    if (near && row_begin == 0) {
        for (int k = 0; k < 3; ++k) {
            int side = sides[k];
            vec2 cell = vec2(float(side) / float(near_strata));
            for (int s = 0; s < near_draws; ++s) {
                uint draw = uint(strata_per_side * strata_per_side + k * near_draws + s);
                vec2 u = fract(vec2(random01(IMAGE_ID, draw, uint(seed) * 2u),
                                    random01(IMAGE_ID, draw, uint(seed) * 2u + 1u)) + offset.xy);
                vec2 within = (vec2(s % near_strata, s / near_strata) + u) * cell;
                ivec2 t = centre - side / 2 + min(ivec2(within), ivec2(side - 1));
                if (any(lessThan(t, ivec2(0))) || any(greaterThanEqual(t, rsm_size))) {
                    continue;  // off the map: no light there, and its density counted all the same
                }
                float density = strata_density(t, rsm_size, guided, weight)
                                + near_density(t, centre, sides, densities);
                irradiance += vpl_light(t, x, n, disk_share) / density;
            }
        }
    }
    vec4 acc = imageLoad(indirect, px);
    imageStore(indirect, px, acc + vec4(set_weight * irradiance / PI, 0.0));
}
