"""Edge-aware a-trous denoise: per-pixel noise (vct's jittered cones, rsm's VPL speckles) averaged out
over each surface, never across geometry edges (gpu_shaders/common/denoise.comp.glsl; `reference` is
its numpy twin, used by the tests).

Inputs: `gbuf` {position, normal} (RGBA32F, camera pixels or lightmap texels: position in world metres
with w = coverage, normal unit), `noisy` (RGBA32F, same size: an irradiance-like product, all four
channels filtered: indirect, glossy or ao, never anything already multiplied by albedo). Output: `out`
(RGBA32F, same size, written), in the units of `noisy`. `scratch` (RGBA32F, same size) holds the odd
iterations when there are two or more. `noisy`, `out` and `scratch` must be three different textures:
an iteration reads one and writes another.

Each iteration k (`Params.iterations` in all) replaces every covered pixel with the normalised,
weighted mean of 5 x 5 taps 2^k pixels apart (the B3-spline kernel, `KERNEL`); the weights come only
from the G-buffer, so the filter is linear in `noisy`, a flat field stays flat and the energy of a
noisy field over a surface stays put. A tap's weight is the kernel times normal agreement
max(0, n . n_q)^normal_power times exp(-(plane^2 + excess^2)), where, in units of the pixel's
footprint f (the world distance to its nearest covered neighbour along x and along y, the larger of
the two):
- plane = |n . (p_q - p)| / (plane_sigma_footprints f): distance from the pixel's tangent plane, so
  two surfaces at different depths do not mix;
- excess = max(0, |p_q - p| - |o| f) / (position_sigma_footprints |o| f), |o| the tap's offset in
  pixels: how much farther the tap lies than its offset on the pixel's own surface would put it, so
  neighbours in the image that are apart in space (silhouettes; a lightmap's UV charts, whose texels
  are neighbours in UV only) get ~0 weight.
Pixels with coverage 0 are written 0 and weigh nothing; a covered pixel without a covered neighbour
keeps its value. After k iterations the kernel reaches 2 (2^k - 1) pixels (`iterations_for` picks k
for an image size); `noise_factor` is the standard deviation it leaves of i.i.d. noise on a plane.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..backends.base import Backend, Image, Sampler, ShaderSpec, Var, group_count
from .declare import GBUF_NORMAL, GBUF_POSITION, INDIRECT, PassDecl

# The B3 spline (1, 4, 6, 4, 1) / 16 of the a-trous wavelet transform, taps -2..2; the shader's b3().
KERNEL = np.array([1.0, 4.0, 6.0, 4.0, 1.0]) / 16.0


# The kernel's reach, 2 (2^k - 1) px after k iterations, as a share of the image's long side
# (`iterations_for`). The filter is guided by geometry only, so it also flattens the indirect's real rise
# into concave corners once it reaches that far. On cornell, vct's indirect against Cycles (512 spp;
# rel_rmse / rel_rmse_8, unfiltered 0.60 / 0.15) was best with 2 iterations at 128 px (0.175 / 0.125;
# 3: 0.21 / 0.15), 3 at 256 px (0.162 / 0.129; 2: 0.172 / 0.138, 4: 0.21 / 0.17) and 3 to 4 at 512 px
# (0.155 / 0.131 and 0.157 / 0.129; 2: 0.169 / 0.140): reaches of 4.7 %, 5.5 % and 2.7 to 5.9 % of the
# long side (tools/denoise_cost.py).
REACH_FRACTION = 0.05


def iterations_for(long_side_px: int) -> int:
    """The iterations whose reach is nearest REACH_FRACTION of the long side: 2 at 128 px, 3 at 256,
    4 at 512, 5 at 1024."""
    return max(1, round(math.log2(REACH_FRACTION * long_side_px / 2 + 1)))


@dataclass(frozen=True)
class Params:
    # Iterations, each with twice the previous tap spacing (1, 2, 4, ... px); callers pass
    # iterations_for(their image's long side). Three (GIConfig's default 256 px) leave a kernel of
    # standard deviation sqrt(1 + 4 + 16) = 4.6 px per axis, which cuts i.i.d. noise 16.6-fold
    # (`noise_factor`).
    iterations: int = 3
    # Exponent on max(0, n . n_q): a tap whose normal is 15 degrees off weighs 0.33, 30 degrees 0.01,
    # so creases stay sharp while smooth-shaded curves still blur at small tap spacings.
    normal_power: float = 32.0
    # Distance from the pixel's tangent plane (in pixel footprints) at which a tap's weight falls to
    # 1/e: a depth step of two footprints weighs 0.02.
    plane_sigma_footprints: float = 1.0
    # Excess distance beyond the tap's offset on the pixel's own surface, in footprints per pixel of
    # offset, at which a tap's weight falls to 1/e: the slack lets perspective stretch a surface by
    # ~2x across the kernel; a chart 1 m away across a lightmap seam, or a silhouette, weighs ~0.
    position_sigma_footprints: float = 1.0


SPEC = ShaderSpec(
    name="denoise",
    compute="common/denoise.comp.glsl",
    local_size=(8, 8, 1),
    samplers=(Sampler("gbuf_position", "2D"), Sampler("gbuf_normal", "2D"), Sampler("source", "2D")),
    images=(Image("filtered", "2D"),),
    uniforms=(Var("step_px", "int"), Var("normal_power", "float"), Var("plane_sigma", "float"),
              Var("position_sigma", "float")),
)


DECL = PassDecl("denoise", "gather", (GBUF_POSITION, GBUF_NORMAL, INDIRECT), (INDIRECT,),
                "a stochastic gather's products (indirect; vct's ao and glossy too) filtered along their "
                "surfaces (GIConfig.denoise)")


def _destinations(iterations: int, noisy, out, scratch) -> list:
    """The texture each iteration writes, alternating so that the last one writes `out`."""
    if iterations < 1:
        raise ValueError(f"denoise: iterations must be >= 1, not {iterations}")
    if iterations > 1 and scratch is None:
        raise ValueError("denoise: two or more iterations need a scratch texture")
    if noisy is out or noisy is scratch or out is scratch:
        raise ValueError("denoise: noisy, out and scratch must be different textures")
    return [out if (iterations - 1 - k) % 2 == 0 else scratch for k in range(iterations)]


def run(backend: Backend, gbuf: dict, noisy, out, scratch=None, params: Params = Params()) -> None:
    """out := `noisy` filtered (module docstring); `scratch` is needed for two or more iterations."""
    program = backend.program(SPEC)
    groups = group_count(out.size, SPEC.local_size)
    source = noisy
    for k, dest in enumerate(_destinations(params.iterations, noisy, out, scratch)):
        backend.dispatch(program, groups,
                         uniforms={"step_px": 1 << k, "normal_power": params.normal_power,
                                   "plane_sigma": params.plane_sigma_footprints,
                                   "position_sigma": params.position_sigma_footprints},
                         samplers={"gbuf_position": gbuf["position"], "gbuf_normal": gbuf["normal"],
                                   "source": source},
                         images={"filtered": dest})
        source = dest


# -- numpy reference (float64; the tests compare the pass with it) ------------------------------------

def _shifted(a: np.ndarray, dy: int, dx: int) -> np.ndarray:
    """b[y, x] = a[y + dy, x + dx], zero (no coverage, no value) outside the image."""
    h, w = a.shape[:2]
    b = np.zeros_like(a)
    ys, yd = slice(max(dy, 0), h + min(dy, 0)), slice(max(-dy, 0), h + min(-dy, 0))
    xs, xd = slice(max(dx, 0), w + min(dx, 0)), slice(max(-dx, 0), w + min(-dx, 0))
    b[yd, xd] = a[ys, xs]
    return b


def footprint_m(position: np.ndarray) -> np.ndarray:
    """(h, w) pixel footprints (m): per axis the distance to the nearer covered neighbour, the larger of
    the two axes; -1 where no neighbour is covered."""
    pos, cov = position[..., :3], position[..., 3] != 0
    axes = []
    for dy, dx in ((0, 1), (1, 0)):
        nearest = np.full(cov.shape, np.inf)
        for side in (-1, 1):
            q_cov = _shifted(cov, side * dy, side * dx)
            d = np.linalg.norm(_shifted(pos, side * dy, side * dx) - pos, axis=-1)
            nearest = np.where(q_cov, np.minimum(nearest, d), nearest)
        axes.append(np.where(np.isfinite(nearest), nearest, -1.0))
    return np.maximum(*axes)


def _iteration(pos, cov, nrm, footprint, src, step_px: int, params: Params) -> np.ndarray:
    total = np.zeros(cov.shape)
    acc = np.zeros(src.shape)
    scale = np.where(footprint > 0, footprint, 1.0)  # pixels without a footprint keep their value below
    for j in range(-2, 3):
        for i in range(-2, 3):
            dy, dx = j * step_px, i * step_px
            w = KERNEL[i + 2] * KERNEL[j + 2] * _shifted(cov, dy, dx)
            if i or j:
                d = _shifted(pos, dy, dx) - pos
                facing = np.maximum(np.sum(nrm * _shifted(nrm, dy, dx), axis=-1), 0.0) ** params.normal_power
                plane = np.abs(np.sum(nrm * d, axis=-1)) / (params.plane_sigma_footprints * scale)
                expected = np.hypot(dx, dy) * scale
                excess = np.maximum(np.linalg.norm(d, axis=-1) - expected, 0.0) / (
                    params.position_sigma_footprints * expected)
                w = w * facing * np.exp(-(plane**2 + excess**2))
            acc += w[..., None] * _shifted(src, dy, dx)
            total += w
    filtered = np.where((footprint > 0)[..., None], acc / np.maximum(total, 1e-300)[..., None], src)
    return np.where(cov[..., None], filtered, 0.0)


def reference(position: np.ndarray, normal: np.ndarray, noisy: np.ndarray, params: Params = Params()) -> np.ndarray:
    """What `run` computes, on (h, w, 4) arrays (G-buffer position and normal, the noisy product), in float64."""
    position, normal, src = (np.asarray(a, np.float32).astype(np.float64) for a in (position, normal, noisy))
    pos, cov, nrm = position[..., :3], position[..., 3] != 0, normal[..., :3]
    footprint = footprint_m(position)
    for k in range(params.iterations):
        src = _iteration(pos, cov, nrm, footprint, src, 1 << k, params)
    return src


def noise_factor(iterations: int) -> float:
    """The standard deviation i.i.d. unit noise keeps, far from edges on a plane (all G-buffer weights
    1): sqrt(sum of the squared weights) of the iterations' kernels convolved, the k-th spread 2^k px."""
    kernel_1d = np.ones(1)
    for k in range(iterations):
        spread = np.zeros(4 * (1 << k) + 1)
        spread[:: 1 << k] = KERNEL
        kernel_1d = np.convolve(kernel_1d, spread)
    # The 2D kernel is separable: its sum of squares is the 1D one's squared, whose square root is this.
    return float(np.sum(kernel_1d**2))
