"""Edge-aware a-trous denoise: per-pixel noise (vct's jittered cones, rsm's VPL speckles) averaged out
over each surface, never across geometry edges (gpu_shaders/common/denoise.comp.glsl; `reference` is
its numpy twin, used by the tests).

Inputs: `gbuf` {position, normal} (RGBA32F, camera pixels or lightmap texels: position in world metres
with w = coverage, normal unit), `noisy` (RGBA32F, same size: an irradiance-like product, all four
channels filtered: indirect, glossy or ao, never anything already multiplied by albedo). Output: `out`
(RGBA32F, same size, written), in the units of `noisy`. `scratch` (RGBA32F, same size) holds the odd
iterations when there are two or more. `noisy`, `out` and `scratch` must be three different textures:
an iteration reads one and writes another. `guide` (RGBA32F, same size) holds what the first iteration
measures for the later ones: each pixel's footprint, and the luminance spread the guided iteration
needs (its taps are the first iteration's), so neither is computed twice.

Each iteration k (`Params.iterations` in all) replaces every covered pixel with the normalised,
weighted mean of 5 x 5 taps 2^k pixels apart (the B3-spline kernel, `KERNEL`); the weights come only
from the G-buffer, so these iterations are linear in `noisy`, a flat field stays flat and the energy of a
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

With `Params.guided` one more iteration follows, 2^k pixels apart, whose taps also weigh
exp(-|l_q - l| / (luminance_sigma sd)): l the luminance of the k iterations' output, sd the noise left
in it, estimated per pixel as the standard deviation of `noisy`'s luminance over its 5 x 5 taps 1 px
apart times noise_factor(k) (SVGF's edge-stopping function, Schied et al. 2017, from one image). Real
gradients, which differ by more than the noise, stop it; the residual blotches of the geometric
iterations, which differ by about the noise, are averaged once more. That iteration looks at the
values, so it is not linear; a flat field still stays flat, and the energy of a noisy plane stays
within 1 % (tests/gpu/test_denoise.py).
"""

from __future__ import annotations

import functools
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
    # One more iteration after `iterations`, stopped by luminance differences beyond the noise (module
    # docstring). Cornell 128 px (noise between seeds / rel_rmse_8 / bias, tools/noise_table.py): vct
    # 0.083 / 0.116 / 0.951 -> 0.066 / 0.117 / 0.946, rsm 0.041 / 0.195 / 1.135 -> 0.031 / 0.197 / 1.134;
    # a third geometric iteration instead: vct 0.041 / 0.147, rsm 0.032 / 0.230 (real gradients flatten).
    guided: bool = True
    # Luminance difference, in units of the estimated noise, at which a guided tap's weight falls to
    # 1/e: SVGF's 4. 2: vct 0.074; 8: vct 0.058 / 0.123, per-pixel rel_rmse against Cycles 0.174 against
    # 0.167 (gradients start to flatten).
    luminance_sigma: float = 4.0
    # Excess distance beyond the tap's offset on the pixel's own surface, in footprints per pixel of
    # offset, at which a tap's weight falls to 1/e: the slack lets perspective stretch a surface by
    # ~2x across the kernel; a chart 1 m away across a lightmap seam, or a silhouette, weighs ~0.
    position_sigma_footprints: float = 1.0


def weight_uniforms(params: Params) -> dict:
    """The G-buffer weights' uniforms (common/gbuffer_weight.glsl)."""
    return {"normal_power": params.normal_power, "plane_sigma": params.plane_sigma_footprints,
            "position_sigma": params.position_sigma_footprints}


# Products one dispatch filters together (vct's indirect, ao and glossy): their G-buffer weights, most of
# an iteration's work, are computed once per tap. At 1920 x 1080 on an NVIDIA H200 vct's three products
# took 10.3 ms filtered one at a time and 5.0 ms together; one product alone 3.4 ms (benchmarks/gpu).
MAX_PRODUCTS = 3
_UNIFORMS = (Var("step_px", "int"), Var("normal_power", "float"), Var("plane_sigma", "float"),
             Var("position_sigma", "float"))


# The three kinds of iteration (common/denoise.comp.glsl): the first measures each pixel's footprint and
# its products' luminance spread into the guide texture, the geometric ones after it read the footprint,
# the guided one both.
STAGES = ("first", "next", "guided")


@functools.cache  # one spec, hence one program, per (product count, stage)
def spec(products: int, stage: str) -> ShaderSpec:
    """The iteration filtering `products` images (source0.., written to filtered0..) at `stage`
    (STAGES)."""
    if not 1 <= products <= MAX_PRODUCTS:
        raise ValueError(f"denoise: 1 to {MAX_PRODUCTS} products per dispatch, not {products}")
    if stage not in STAGES:
        raise ValueError(f"denoise: stage is one of {STAGES}, not {stage!r}")
    first = stage == "first"
    samplers = (Sampler("gbuf_position", "2D"), Sampler("gbuf_normal", "2D"),
                *(Sampler(f"source{k}", "2D") for k in range(products)),
                *(() if first else (Sampler("guide", "2D"),)))
    guided = stage == "guided"
    uniforms = (*_UNIFORMS, Var("luminance_sigma", "float"), Var("raw_noise_factor", "float")) if guided else _UNIFORMS
    return ShaderSpec(
        name=f"denoise{products}_{stage}",
        compute="common/denoise.comp.glsl",
        local_size=(8, 8, 1),
        samplers=samplers,
        images=(*(Image(f"filtered{k}", "2D") for k in range(products)), *((Image("guide", "2D"),) if first else ())),
        uniforms=uniforms,
        defines=(("PRODUCTS", str(products)), *((("FIRST", "1"),) if first else ()),
                 *((("GUIDED", "1"),) if guided else ())),
    )


DECL = PassDecl("denoise", "gather", (GBUF_POSITION, GBUF_NORMAL, INDIRECT), (INDIRECT,),
                "a stochastic gather's products (indirect; vct's ao and glossy too) filtered along their "
                "surfaces (GIConfig.denoise)")


def _destinations(passes: int, noisy, out, scratch) -> list:
    """The texture each pass writes, alternating so that the last one writes `out`."""
    if passes > 1 and scratch is None:
        raise ValueError("denoise: two or more passes (iterations, and the guided one) need a scratch texture")
    if noisy is out or noisy is scratch or out is scratch:
        raise ValueError("denoise: noisy, out and scratch must be different textures")
    return [out if (passes - 1 - k) % 2 == 0 else scratch for k in range(passes)]


def _as_list(textures) -> list:
    return list(textures) if isinstance(textures, (list, tuple)) else [textures]


def run(backend: Backend, gbuf: dict, noisy, out, scratch=None, params: Params = Params(), *, guide) -> None:
    """out := `noisy` filtered (module docstring); `scratch` is needed for two or more passes (the
    iterations, and the guided one). `noisy`, `out` and `scratch` are one texture each, or lists of as
    many (up to MAX_PRODUCTS) of the same size: products of one image, filtered in the same dispatches,
    each exactly as alone. `guide` (RGBA32F, the same size, one for all products) holds what the first
    iteration measures for the others: each pixel's footprint and its products' noise."""
    noisy, out = _as_list(noisy), _as_list(out)
    scratch = [None] * len(noisy) if scratch is None else _as_list(scratch)
    if not len(noisy) == len(out) == len(scratch):
        raise ValueError("denoise: as many noisy, out and scratch textures")
    if params.iterations < 1:
        raise ValueError(f"denoise: iterations must be >= 1, not {params.iterations}")
    passes = params.iterations + int(params.guided)
    dests = [_destinations(passes, *textures) for textures in zip(noisy, out, scratch, strict=True)]
    if guide is None or any(guide is t for t in (*noisy, *out, *scratch)):
        raise ValueError("denoise: a guide texture of its own is needed")
    groups = group_count(out[0].size, spec(len(noisy), "first").local_size)
    sources = noisy
    for k in range(passes):
        stage = "first" if k == 0 else ("guided" if k == params.iterations else "next")
        uniforms = {"step_px": 1 << k, **weight_uniforms(params)}
        samplers = {"gbuf_position": gbuf["position"], "gbuf_normal": gbuf["normal"],
                    **{f"source{i}": t for i, t in enumerate(sources)}}
        written = [d[k] for d in dests]
        images = {f"filtered{i}": t for i, t in enumerate(written)}
        if stage == "first":
            images["guide"] = guide
        else:
            samplers["guide"] = guide
        if stage == "guided":
            uniforms.update(luminance_sigma=params.luminance_sigma, raw_noise_factor=noise_factor(params.iterations))
        backend.dispatch(backend.program(spec(len(noisy), stage)), groups, uniforms=uniforms, samplers=samplers,
                         images=images)
        sources = written


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


# Rec. 709 luminance: the guided iteration compares these (the shader's LUMA).
LUMA = np.array([0.2126, 0.7152, 0.0722])


def _taps(pos, cov, nrm, footprint, step_px: int, params: Params):
    """(dy, dx, G-buffer weight) of the 25 taps `step_px` apart, the kernel included."""
    scale = np.where(footprint > 0, footprint, 1.0)  # pixels without a footprint keep their value
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
            yield dy, dx, w


def _iteration(pos, cov, nrm, footprint, src, step_px: int, params: Params, noise_sd=None) -> np.ndarray:
    """One iteration; with `noise_sd` (per pixel) the guided one."""
    total = np.zeros(cov.shape)
    acc = np.zeros(src.shape)
    luminance = src[..., :3] @ LUMA
    for dy, dx, w in _taps(pos, cov, nrm, footprint, step_px, params):
        if noise_sd is not None and (dy or dx):
            scale = params.luminance_sigma * noise_sd + 1e-30
            w = w * np.exp(-np.abs(_shifted(luminance, dy, dx) - luminance) / scale)
        acc += w[..., None] * _shifted(src, dy, dx)
        total += w
    filtered = np.where((footprint > 0)[..., None], acc / np.maximum(total, 1e-300)[..., None], src)
    return np.where(cov[..., None], filtered, 0.0)


def _raw_deviation(pos, cov, nrm, footprint, raw, params: Params) -> np.ndarray:
    """Standard deviation of `raw`'s luminance over the 5 x 5 taps 1 px apart, with the filter's weights."""
    luminance = raw[..., :3] @ LUMA
    m1, m2, total = np.zeros(cov.shape), np.zeros(cov.shape), np.zeros(cov.shape)
    for dy, dx, w in _taps(pos, cov, nrm, footprint, 1, params):
        q = _shifted(luminance, dy, dx)
        m1, m2, total = m1 + w * q, m2 + w * q * q, total + w
    total = np.maximum(total, 1e-300)
    return np.sqrt(np.maximum(m2 / total - (m1 / total) ** 2, 0.0))


def reference(position: np.ndarray, normal: np.ndarray, noisy: np.ndarray, params: Params = Params()) -> np.ndarray:
    """What `run` computes, on (h, w, 4) arrays (G-buffer position and normal, the noisy product), in float64."""
    position, normal, raw = (np.asarray(a, np.float32).astype(np.float64) for a in (position, normal, noisy))
    pos, cov, nrm = position[..., :3], position[..., 3] != 0, normal[..., :3]
    footprint = footprint_m(position)
    src = raw
    for k in range(params.iterations):
        src = _iteration(pos, cov, nrm, footprint, src, 1 << k, params)
    if params.guided:
        noise_sd = _raw_deviation(pos, cov, nrm, footprint, raw, params) * noise_factor(params.iterations)
        src = _iteration(pos, cov, nrm, footprint, src, 1 << params.iterations, params, noise_sd)
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
