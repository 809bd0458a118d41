// The diffuse gather through the radiance pyramid (needs the uniform diffuse_cones besides cone.glsl's).
#include "vct/cone.glsl"

// Diffuse gather about normal n at position p (m): `diffuse_cones` cones, one per band of equal
// projected solid angle (cos^2 theta in [1 - (i + 1) / N, 1 - i / N]: each band holds 1 / N of the
// cosine-weighted hemisphere), at cos theta = sqrt(1 - (i + jitter) / N) and a golden-angle spiral in phi
// turned by `rotation`; the cones weigh the same, so a uniform environment of radiance L returns exactly
// L. Cosine-distributed rather than bands of equal solid angle weighted by cos theta: the latter spent
// half of the cones below 30 degrees of elevation, which held a quarter of the weight (noise between seeds,
// 128 px: cornell 0.039 -> 0.031, Sponza 0.081 -> 0.068; docs/VCT.md). The side cap makes each cone a
// narrow probe of its band: with fixed elevations the probes never looked along the normal
// (a small source straight ahead read 0.16 at 24 cells); with the per-receiver jitter and rotation
// (uniform in [0, 1) and [0, 2 pi)) every direction is probed on average, and neighbouring pixels
// average the noise. The cone's width is that of 2 pi / N sr, the bands' mean solid angle. `dither`
// (uniform in [0, 1)) rounds cone i's levels with dither + i x the golden ratio (trace_cone). Returns
// (E / pi, the cosine-weighted opacity).
//
// `gather` of `gathers` (0 of 1 for a single gather): the gathers of a pixel as one spiral of gathers x
// diffuse_cones cones, this gather tracing every gathers-th cone from the gather-th on: cone
// k = i x gathers + gather at cos theta = sqrt(1 - (k + jitter) / (gathers x diffuse_cones)), azimuth
// k x the golden angle. Each band's gathers fill its sub-bands and the union is as evenly spread as one
// gather's cones. Each gather alone samples part of every band; the mean of all `gathers` is unbiased.
// (vct/gather.comp.glsl says when the gathers take this form.)
const float GOLDEN_ANGLE = 2.39996323;  // radians: pi (3 - sqrt(5))

vec4 gather_diffuse(vec3 p, vec3 n, float rotation, float jitter, float dither, int gather, int gathers) {
    vec3 tx, ty;
    tangent_frame(n, tx, ty);
    vec3 g0 = (p - grid_origin) / cell_size + offset_cells * n;
    float cos_half = 1.0 - 1.0 / float(diffuse_cones);
    float tan_half = sqrt(max(1.0 - cos_half * cos_half, 0.0)) / cos_half;
    vec4 sum = vec4(0.0);
    float spiral_cones = float(diffuse_cones * gathers);
    for (int i = 0; i < diffuse_cones; i++) {
        float k = float(i * gathers + gather);
        float z = max(sqrt(1.0 - (k + jitter) / spiral_cones), 1e-3);
        float r = sqrt(max(1.0 - z * z, 0.0));
        float phi = GOLDEN_ANGLE * k + rotation;
        vec3 d = normalize(tx * (r * cos(phi)) + ty * (r * sin(phi)) + n * z);
        sum += trace_cone(g0, d, tan_half, dot(d, n), SIDE_CAP, fract(dither + 0.61803399 * float(i)));
    }
    return sum / float(diffuse_cones);
}
