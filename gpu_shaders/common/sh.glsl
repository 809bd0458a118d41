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

// L2 (9 coefficients: the L1 order, then xy, yz, 3z^2-1, xz, x^2-y^2), as sh.py's basis_l2. Coefficient
// i of the basis and of the clamped-cosine lobe (band factors pi, 2 pi / 3, pi / 4).
const float SH_Y2_XY = 1.09254843;   // sqrt(15 / pi) / 2 (xy, yz, xz)
const float SH_Y2_ZZ = 0.31539157;   // sqrt(5 / pi) / 4 (3z^2 - 1)
const float SH_Y2_XXYY = 0.54627422; // sqrt(15 / pi) / 4 (x^2 - y^2)
const float SH_A2 = 0.78539816;      // pi / 4, l = 2

float sh2_basis(int i, vec3 d) {
    if (i < 4) {
        return sh_basis(d)[i];
    }
    if (i == 4) {
        return SH_Y2_XY * d.x * d.y;
    }
    if (i == 5) {
        return SH_Y2_XY * d.y * d.z;
    }
    if (i == 6) {
        return SH_Y2_ZZ * (3.0 * d.z * d.z - 1.0);
    }
    if (i == 7) {
        return SH_Y2_XY * d.x * d.z;
    }
    return SH_Y2_XXYY * (d.x * d.x - d.y * d.y);
}

// The clamped-cosine lobe with sh.py's IRRADIANCE_WINDOW_L2 per band (1, 0.9, 0.64): the Hann window
// under which a single bright direction's L2 irradiance is 0 at the opposite normal (sh.py says why).
const float SH_WINDOW1 = 0.9;
const float SH_WINDOW2 = 0.64;

float sh2_windowed_cosine_lobe(int i, vec3 n) {
    return (i == 0 ? SH_A0 : (i < 4 ? SH_WINDOW1 * SH_A1 : SH_WINDOW2 * SH_A2)) * sh2_basis(i, n);
}
