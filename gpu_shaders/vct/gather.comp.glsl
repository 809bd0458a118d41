// VCT gather at the camera's pixels: indirect = E / pi (Cycles' Diffuse Indirect units) from the
// diffuse cones about the G-buffer normal; ambient occlusion (the cosine-weighted opacity) in `ao`.
// With scale > 1 the images are 1/scale of the G-buffer's size and each texel gathers at the centre
// pixel of its scale x scale block (upsample.comp.glsl brings them back to full size).
#include "vct/diffuse.glsl"
#include "vct/source_pixel.glsl"
#include "common/pixel_pattern.glsl"

// n gathers trace one spiral where n x the golden angle is closer than this to a whole turn (below).
const float SPIRAL_BELOW_TURN = 0.2;
// The streams of the image's three random numbers: random01(stream, stream, seed).
const uvec3 PATTERN_STREAMS = uvec3(0x2c1b3c6du, 0x5bd1e995u, DITHER_STREAM);

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
    // Each pixel's (jitter, rotation, dither): the image's random numbers plus the pixel pattern
    // (common/pixel_pattern.glsl), which replaced 8 x 8 tiles of a 64-phase lattice with a random shift
    // per tile (Keller & Heidrich's interleaved sampling): their per-tile errors were independent and
    // passed the filter as blotches. docs/VCT.md has the noise figures; of the pattern's steps tried,
    // others (the 3-dimensional R sequence's, p's turned by 90 degrees, two picked by a Fourier
    // criterion) read 0.040-0.084 on cornell at 128 px, against these 0.037-0.039. New random numbers
    // per refinement gather instead of the pattern's sample step: cornell 128 px, 16 gathers, 0.0115
    // against 0.0081, Sponza 0.0177 against 0.0118; two other steps of the same search read 0.0131 and
    // 0.0151 on Sponza.
    uint s = uint(seed) * 2u;
    vec3 image_random = vec3(random01(PATTERN_STREAMS.x, PATTERN_STREAMS.x, s),
                             random01(PATTERN_STREAMS.y, PATTERN_STREAMS.y, s),
                             random01(PATTERN_STREAMS.z, PATTERN_STREAMS.z, s));
    vec3 u = fract(image_random + pixel_pattern(px, sample_index));
    float jitter = u.x, rotation = 6.28318531 * u.y, dither = u.z;
    // Every pixel gathers `image_gathers` times (GIConfig.sample_budget_px: a small image, whose filter
    // has few pixels to average, spends the gathers a larger one would), and where the denoise filter will
    // find little of the pixel's own surface around it (`support`, from passes/surface_support.py, at the
    // pixel the texel stands for), which it cannot average, `support_gathers` times that.
    int gathers = image_gathers;
    if (support_gathers > 1 && texelFetch(support, src, 0).x < support_threshold) {
        gathers *= support_gathers;
    }
    // Gather g of n is turned, jittered and dithered a further g / n of the way, so the set stays
    // stratified; its cones are the first gather's turned. That leaves them on few azimuths where n x
    // the golden angle (cone i's azimuth is i x 0.382 of a turn) is near a whole number of turns: cone i
    // of gather g then lies near (i x round(0.382 n) + g) / n of a turn, on the same n azimuths in every
    // gather. There the n gathers trace one spiral of n x diffuse_cones cones instead (vct/diffuse.glsl).
    // Sponza, 128 px, every pixel n gathers, noise between seeds (docs/VCT.md, "Several gathers of a
    // pixel"): turned,
    // n = 3 / 5 / 8 / 16 (0.146 / 0.090 / 0.056 / 0.111 of a turn from whole) 0.077 / 0.048 / 0.035 /
    // 0.015, against 0.024 / 0.022 / 0.018 / 0.014 at n = 6 / 7 / 9 / 12 (0.29 / 0.33 / 0.44 / 0.42);
    // one spiral 0.040 at 3 and 0.018 at 8, 0.010 at 16. Turned gathers stay where they are not near a
    // whole turn: at n = 4 the spiral read more noise on the boxes (cornell 0.021 against 0.016,
    // window-room 0.053 against 0.034).
    bool one_spiral = abs(fract(float(gathers) * GOLDEN_ANGLE / 6.28318531 + 0.5) - 0.5) < SPIRAL_BELOW_TURN;
    vec4 e = vec4(0.0);
    for (int g = 0; g < gathers; g++) {
        // One call with chosen arguments: pixels of both kinds share a SIMD group, which would run two calls.
        float t = float(g) / float(gathers);
        float turn = one_spiral ? 0.0 : t;
        e += gather_diffuse(pos.xyz, n, rotation + 6.28318531 * turn, fract(jitter + turn), fract(dither + t),
                            one_spiral ? g : 0, one_spiral ? gathers : 1);
    }
    e /= float(gathers);
    imageStore(indirect, px, vec4(e.rgb, 1.0));
    imageStore(ao, px, vec4(vec3(1.0 - e.a), 1.0));
}
