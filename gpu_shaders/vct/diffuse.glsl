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
vec4 gather_diffuse(vec3 p, vec3 n, float rotation, float jitter, float dither) {
    vec3 tx, ty;
    tangent_frame(n, tx, ty);
    vec3 g0 = (p - grid_origin) / cell_size + offset_cells * n;
    float cos_half = 1.0 - 1.0 / float(diffuse_cones);
    float tan_half = sqrt(max(1.0 - cos_half * cos_half, 0.0)) / cos_half;
    vec4 sum = vec4(0.0);
    for (int i = 0; i < diffuse_cones; i++) {
        float z = max(sqrt(1.0 - (float(i) + jitter) / float(diffuse_cones)), 1e-3);
        float r = sqrt(max(1.0 - z * z, 0.0));
        float phi = 2.39996323 * float(i) + rotation;
        vec3 d = normalize(tx * (r * cos(phi)) + ty * (r * sin(phi)) + n * z);
        sum += trace_cone(g0, d, tan_half, dot(d, n), SIDE_CAP, fract(dither + 0.61803399 * float(i)));
    }
    return sum / float(diffuse_cones);
}
