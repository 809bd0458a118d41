"""The GGX glossy lobe's directional albedo, split for a per-pixel F0 (the table the specular cone reads).

With Schlick's Fresnel F = F0 + (1 - F0) Fc, Fc = (1 - v.h)^5, the reflected fraction of light arriving
uniformly from the mirror lobe, E(mu, roughness, F0) = integral of f_GGX cos(theta_l) over the
hemisphere, is linear in F0: E = F0 A + B with

    A = integral (1 - Fc) D G / (4 n.v) dl,   B = integral Fc D G / (4 n.v) dl.

Sampling half vectors from D(h) n.h (pdf of l: D n.h / (4 v.h)) leaves each sample the weight
G v.h / (n.v n.h). G is Smith's height-correlated masking-shadowing 1 / (1 + Lambda(v) + Lambda(l)),
Lambda(x) = (sqrt(1 + alpha^2 tan^2 theta_x) - 1) / 2, alpha = roughness^2 (Blender's convention).
The integrals use a fixed stratified grid of samples, so the table is deterministic.

Single scattering loses the light that bounces between microfacets (E < 1 for F0 = 1 and rough
surfaces); Cycles' Principled BSDF uses multiple-scattering GGX, which keeps it. `multiscatter_factor`
restores it as Fdez-Aguera (2019) does: a white furnace of radiance L seen in a metal of F0 = 1 then
reads exactly L at every roughness and angle.
"""

from __future__ import annotations

import functools

import numpy as np

TABLE_SIZE = 32  # entries along n.v and roughness; texel centres at (i + 0.5) / TABLE_SIZE
_STRATA = 64     # 64 x 64 half-vector samples per entry


def ggx_alpha(roughness):
    """GGX alpha from Blender's Roughness, floored so that a mirror keeps a finite lobe (1e-4 rad wide)."""
    return np.maximum(np.square(roughness), 1e-4)


def smith_lambda(cos_theta: np.ndarray, alpha) -> np.ndarray:
    cos2 = np.clip(cos_theta * cos_theta, 1e-12, 1.0)
    return 0.5 * (np.sqrt(1.0 + alpha * alpha * (1.0 - cos2) / cos2) - 1.0)


def split_albedo(n_dot_v: float, roughness: float, strata: int = _STRATA) -> tuple[float, float]:
    """(A, B) of the module docstring for one view angle and roughness."""
    alpha = float(ggx_alpha(roughness))
    mu = float(np.clip(n_dot_v, 1e-4, 1.0))
    u = (np.arange(strata) + 0.5) / strata
    u1, u2 = np.meshgrid(u, u, indexing="ij")
    # Half vectors from D(h) n.h: tan^2 theta_h = alpha^2 u1 / (1 - u1).
    tan2 = alpha * alpha * u1 / (1.0 - u1)
    cos_h = 1.0 / np.sqrt(1.0 + tan2)
    sin_h = np.sqrt(np.maximum(1.0 - cos_h * cos_h, 0.0))
    phi = 2.0 * np.pi * u2
    h = np.stack([sin_h * np.cos(phi), sin_h * np.sin(phi), cos_h], axis=-1)
    v = np.array([np.sqrt(1.0 - mu * mu), 0.0, mu])
    v_dot_h = h @ v
    light = 2.0 * v_dot_h[..., None] * h - v
    n_dot_l = light[..., 2]
    ok = (n_dot_l > 0.0) & (v_dot_h > 0.0)
    g = 1.0 / (1.0 + smith_lambda(mu, alpha) + smith_lambda(np.where(ok, n_dot_l, 1.0), alpha))
    weight = np.where(ok, g * v_dot_h / (mu * cos_h), 0.0)
    fc = (1.0 - np.clip(v_dot_h, 0.0, 1.0)) ** 5
    n = strata * strata
    return float((weight * (1.0 - fc)).sum() / n), float((weight * fc).sum() / n)


@functools.lru_cache(maxsize=1)
def split_albedo_table() -> np.ndarray:
    """(TABLE_SIZE roughness rows, TABLE_SIZE n.v columns, 4) float32: A, B, 0, 1 at texel centres,
    laid out as a 2D texture sampled at (n.v, roughness)."""
    centres = (np.arange(TABLE_SIZE) + 0.5) / TABLE_SIZE
    table = np.zeros((TABLE_SIZE, TABLE_SIZE, 4), np.float32)
    table[..., 3] = 1.0
    for j, rough in enumerate(centres):
        for i, mu in enumerate(centres):
            table[j, i, :2] = split_albedo(mu, rough)
    return table


def multiscatter_factor(a: np.ndarray, b: np.ndarray, f0: np.ndarray) -> np.ndarray:
    """1 + F0 (1 - E) / E with E = A + B: the energy multiple scattering adds, for a lobe of F0."""
    e = np.maximum(a + b, 1e-4)
    return 1.0 + f0 * (1.0 - e) / e
