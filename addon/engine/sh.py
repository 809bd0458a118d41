"""Real spherical harmonics: the numpy reference for gpu_shaders/common/sh.glsl.

Convention (ARCHITECTURE.md section 4): real SH without Condon-Shortley signs, L1 order (1, y, z, x),
L2 appends (xy, yz, 3z^2-1, xz, x^2-y^2). Grids store radiance by direction of travel.
Irradiance from SH radiance L about a normal n is E(n) = sum_i L_i * A_l * Y_i(n) with the clamped-cosine
band factors A_0 = pi, A_1 = 2 pi / 3, A_2 = pi / 4; `cosine_lobe(n)` returns A_l * Y_i(n).
"""

from __future__ import annotations

import numpy as np

Y00 = 0.5 / np.sqrt(np.pi)  # 0.282095
Y1 = np.sqrt(3.0 / (4.0 * np.pi))  # 0.488603
Y2_XY = 0.5 * np.sqrt(15.0 / np.pi)  # 1.092548 (xy, yz, xz)
Y2_ZZ = 0.25 * np.sqrt(5.0 / np.pi)  # 0.315392 (3z^2 - 1)
Y2_XX_YY = 0.25 * np.sqrt(15.0 / np.pi)  # 0.546274 (x^2 - y^2)

BAND_FACTORS = (np.pi, 2.0 * np.pi / 3.0, np.pi / 4.0)

# Per-band window on the L2 irradiance (Hann, h_l = (1 + cos(pi l / w)) / 2), against L2's ringing: a
# unit intensity from one bright direction d (a sun patch seen by a probe; exact irradiance 1 facing
# it) has the L2 irradiance E(-d) = 1/4 - h_1 / 2 + 5/16 h_2 at the opposite normal, 1/16 unwindowed,
# where the true value is 0. With x = cos(pi / w), h_1 = (1 + x) / 2 and h_2 = x^2, so E(-d) = x (5/16 x - 1/4),
# which vanishes at x = 0.8 (w = 4.88): the widest Hann window (the least blur) that leaks nothing to
# the opposite side; narrower ones go negative there. Band 0 is untouched, so a uniform field keeps
# E = pi L exactly. Used where probes are read (gpu_shaders/common/sh.glsl, sh2_windowed_cosine_lobe;
# docs/PROBES.md, "Deringing").
IRRADIANCE_WINDOW_L2 = (1.0, 0.9, 0.64)


def basis_l1(dirs: np.ndarray) -> np.ndarray:
    """Y_i(d) for unit directions d (..., 3) -> (..., 4) in the order (1, y, z, x)."""
    d = np.asarray(dirs, dtype=np.float64)
    x, y, z = d[..., 0], d[..., 1], d[..., 2]
    return np.stack([np.full_like(x, Y00), Y1 * y, Y1 * z, Y1 * x], axis=-1)


def basis_l2(dirs: np.ndarray) -> np.ndarray:
    """Y_i(d) for unit directions (..., 3) -> (..., 9): L1 order, then xy, yz, 3z^2-1, xz, x^2-y^2."""
    d = np.asarray(dirs, dtype=np.float64)
    x, y, z = d[..., 0], d[..., 1], d[..., 2]
    l2 = np.stack(
        [Y2_XY * x * y, Y2_XY * y * z, Y2_ZZ * (3.0 * z * z - 1.0), Y2_XY * x * z, Y2_XX_YY * (x * x - y * y)],
        axis=-1,
    )
    return np.concatenate([basis_l1(d), l2], axis=-1)


def band_of(index: int) -> int:
    """SH band l of coefficient `index` (0 -> 0, 1..3 -> 1, 4..8 -> 2)."""
    return 0 if index == 0 else (1 if index < 4 else 2)


def cosine_lobe_l1(normals: np.ndarray) -> np.ndarray:
    """Projection of the clamped cosine max(0, n.w) about n: (0.886227, 1.023327 * (n.y, n.z, n.x))."""
    b = basis_l1(normals)
    return b * np.array([BAND_FACTORS[0], BAND_FACTORS[1], BAND_FACTORS[1], BAND_FACTORS[1]])


def cosine_lobe_l2(normals: np.ndarray) -> np.ndarray:
    """Projection of the clamped cosine about n onto L2 (9 coefficients)."""
    factors = np.array([BAND_FACTORS[band_of(i)] for i in range(9)])
    return basis_l2(normals) * factors


def windowed_cosine_lobe_l2(normals: np.ndarray) -> np.ndarray:
    """`cosine_lobe_l2` with each band scaled by IRRADIANCE_WINDOW_L2: what a probe lookup evaluates."""
    window = np.array([IRRADIANCE_WINDOW_L2[band_of(i)] for i in range(9)])
    return cosine_lobe_l2(normals) * window


def irradiance(coeffs: np.ndarray, normals: np.ndarray) -> np.ndarray:
    """E(n) = integral L(w) max(0, n.w) dw from SH radiance (..., 4 or 9), clamped at 0.

    The clamp matters: an L1 reconstruction of a clamped cosine is negative behind the surface.
    """
    c = np.asarray(coeffs, dtype=np.float64)
    lobe = cosine_lobe_l1(normals) if c.shape[-1] == 4 else cosine_lobe_l2(normals)
    return np.maximum(np.sum(c * lobe, axis=-1), 0.0)


def evaluate(coeffs: np.ndarray, dirs: np.ndarray) -> np.ndarray:
    """Radiance reconstructed in direction d: sum_i c_i Y_i(d)."""
    c = np.asarray(coeffs, dtype=np.float64)
    b = basis_l1(dirs) if c.shape[-1] == 4 else basis_l2(dirs)
    return np.sum(c * b, axis=-1)


def sphere_quadrature(n_theta: int = 256, n_phi: int = 512) -> tuple[np.ndarray, np.ndarray]:
    """Directions (N, 3) and solid-angle weights (N,) of a midpoint rule in (cos theta, phi).

    Uniform in cos(theta) so every cell has the same solid angle 4 pi / N: exact for the sphere's
    area, and integrates smooth functions to ~1/N^2.
    """
    mu = -1.0 + (np.arange(n_theta) + 0.5) * (2.0 / n_theta)
    phi = (np.arange(n_phi) + 0.5) * (2.0 * np.pi / n_phi)
    mu, phi = np.meshgrid(mu, phi, indexing="ij")
    s = np.sqrt(1.0 - mu * mu)
    dirs = np.stack([s * np.cos(phi), s * np.sin(phi), mu], axis=-1).reshape(-1, 3)
    weights = np.full(dirs.shape[0], 4.0 * np.pi / dirs.shape[0])
    return dirs, weights


def project(radiance: np.ndarray, dirs: np.ndarray, weights: np.ndarray, order: int = 1) -> np.ndarray:
    """SH coefficients of a sampled function: c_i = sum_k f(d_k) Y_i(d_k) w_k."""
    b = basis_l1(dirs) if order == 1 else basis_l2(dirs)
    return np.einsum("k,ki,k->i", np.asarray(radiance, dtype=np.float64), b, weights)
