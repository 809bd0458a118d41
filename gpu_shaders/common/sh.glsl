// Real L1 spherical harmonics, order (1, y, z, x); the numpy reference is addon/engine/sh.py.
// Grids store radiance by direction of travel: to light a surface with normal n, evaluate the
// irradiance about n from radiance arriving *towards* the surface, i.e. sh_irradiance(c, -n) when the
// grid holds travel directions -- the caller decides, these functions only do the algebra.

const float SH_Y00 = 0.28209479;  // 1 / (2 sqrt(pi))
const float SH_Y1 = 0.48860251;   // sqrt(3 / (4 pi))
const float SH_A0 = 3.14159265;   // clamped-cosine band factor, l = 0
const float SH_A1 = 2.09439510;   // 2 pi / 3, l = 1

vec4 sh_basis(vec3 d) {
    return vec4(SH_Y00, SH_Y1 * d.y, SH_Y1 * d.z, SH_Y1 * d.x);
}

// Projection of max(0, dot(n, w)) onto L1: (0.886227, 1.023327 * (n.y, n.z, n.x)).
vec4 sh_cosine_lobe(vec3 n) {
    return vec4(SH_A0 * SH_Y00, SH_A1 * SH_Y1 * n.y, SH_A1 * SH_Y1 * n.z, SH_A1 * SH_Y1 * n.x);
}

// Irradiance (W/m^2) about n from SH radiance c, clamped at 0 (L1 rings negative behind n).
float sh_irradiance(vec4 c, vec3 n) {
    return max(dot(c, sh_cosine_lobe(n)), 0.0);
}

float sh_evaluate(vec4 c, vec3 d) {
    return dot(c, sh_basis(d));
}
