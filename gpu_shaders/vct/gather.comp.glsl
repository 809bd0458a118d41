// VCT gather at the camera's pixels: indirect = E / pi (Cycles' Diffuse Indirect units) from the
// diffuse cones about the G-buffer normal; ambient occlusion (the cosine-weighted opacity) in `ao`.
// With scale > 1 the images are 1/scale of the G-buffer's size and each texel gathers at the centre
// pixel of its scale x scale block (upsample.comp.glsl brings them back to full size).
#include "vct/diffuse.glsl"
#include "vct/source_pixel.glsl"

// Interleaving tiles are 2^TILE_BITS pixels a side (main).
const int TILE_BITS = 3;
// The tile's phase shift's own stream: random01(tile, hash_u32(stream ^ PHASE_STREAM)).
const uint PHASE_STREAM = 0x2c1b3c6du;

void main() {
    ivec2 px = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(px, imageSize(indirect)))) {
        return;
    }
    ivec2 src = source_pixel(px);
    vec4 pos = texelFetch(gbuf_position, src, 0);
    if (pos.w == 0.0) {
        imageStore(indirect, px, vec4(0.0));
        imageStore(ao, px, vec4(0.0));
        return;
    }
    vec3 n = normalize(texelFetch(gbuf_normal, src, 0).xyz);
    uint s = uint(seed) * 2u;
    // Interleaved sampling (Keller & Heidrich 2001): the 64 pixels of an 8 x 8 tile share the tile's
    // random numbers and each takes its own phase k of a 64-point lattice over (jitter, rotation):
    // jitter (k + u) / 64, rotation a golden-ratio multiple of k plus v. k is the pixel's Bayer index
    // (every 2 x 2 and 4 x 4 block spreads its phases too) plus the tile's random shift, so each pixel's
    // jitter and rotation are still uniform (its estimate unbiased on its own), while the tile's 64 x
    // diffuse_cones directions cover the hemisphere evenly: the denoise filter, which averages
    // neighbours, averages a stratified set rather than independent draws. Cornell 128 px: noise
    // between seeds 0.114 -> 0.072-0.083 (two seed pairs), rel_rmse against Cycles 0.175 -> 0.165
    // (tools/noise_table.py; 4 x 4 tiles 0.08, 16 x 16 0.08).
    int k = 0;
    for (int b = 0; b < TILE_BITS; b++) {
        int xb = (px.x >> b) & 1, yb = (px.y >> b) & 1;
        k += (yb == 0 ? 2 * xb : 3 - 2 * xb) << (2 * (TILE_BITS - 1 - b));  // Bayer: 0 2 / 3 1 per level
    }
    uvec2 tile = uvec2(px >> TILE_BITS);
    int phases = 1 << (2 * TILE_BITS);
    k = (k + int(random01(tile.x, tile.y, hash_u32(s ^ PHASE_STREAM)) * float(phases))) % phases;
    // Progressive refinement: the n-th gather (sample_index) keeps the update's random numbers and
    // moves (jitter, rotation) by n x the R2 sequence's steps (Roberts 2018: the plastic number's
    // inverse powers) and the dither by n x the golden ratio, so each pixel's samples form one
    // low-discrepancy set rather than independent draws (still uniform each, so unbiased). Cornell
    // 128 px, 16 samples: noise 0.021 with a fresh seed per sample (1 / sqrt(16) of one's), 0.011 so.
    float i = float(sample_index);
    float jitter = fract((float(k) + random01(tile.x, tile.y, s + 1u)) / float(phases) + i * 0.75487767);
    float rotation = 6.28318531 * fract(random01(tile.x, tile.y, s) + 0.61803399 * float(k) + i * 0.56984029);
    float dither = fract(random01(uint(px.x), uint(px.y), hash_u32(s ^ DITHER_STREAM)) + i * 0.61803399);
    vec4 e = gather_diffuse(pos.xyz, n, rotation, jitter, dither);
    // Where the denoise filter will find little of the pixel's own surface around it (`support`, from
    // passes/surface_support.py, at the pixel the texel stands for), it cannot average this gather's
    // noise: such pixels gather `support_gathers` times, each turned and jittered a further
    // 1 / support_gathers of the way, so the set stays stratified.
    if (support_gathers > 1 && texelFetch(support, src, 0).x < support_threshold) {
        for (int g = 1; g < support_gathers; g++) {
            float t = float(g) / float(support_gathers);
            e += gather_diffuse(pos.xyz, n, rotation + 6.28318531 * t, fract(jitter + t), fract(dither + t));
        }
        e /= float(support_gathers);
    }
    imageStore(indirect, px, vec4(e.rgb, 1.0));
    imageStore(ao, px, vec4(vec3(1.0 - e.a), 1.0));
}
