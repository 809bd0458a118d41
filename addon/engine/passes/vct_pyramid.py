"""VCT radiance pyramid: level 0 from the injected flux, the levels above by opacity compositing.

Every set of six textures is a dict keyed by direction ("px" .. "nz", vct_inject.DIRECTIONS).
Layout (gpu_shaders/vct/pyramid.glsl): six RGBA16F 3D textures, one per axis direction t of travel,
every level side by side along x; level l has dims ceil(dims / 2^l); cone.glsl samples one level per
step, chosen by dithering between the two around the cone's width. rgb = premultiplied radiance
(W/m^2/sr over the cell's cross-section) x radiance_scale(), a = opacity, as met by a ray travelling
along -t.

Passes:
- level0: (flux atlas (vct_inject) x atlas_weight / (pi h^2) [+ later bounces' colours `add_*`]) x
  radiance_scale -> level 0 colours; opacity min(1, projected area / h^2) from the voxelizer's `vox_projected`.
- downsample (one dispatch per level): 2x2x2 children composited front to back along t, the four
  pairs averaged (no second premultiplication).
- accumulate: sum_* = next_* (first) or sum_* + next_* (the bounces after the first, level 0).
"""

from __future__ import annotations

import math

import numpy as np

from ..backends.base import Backend, Image, Sampler, ShaderSpec, Var, group_count
from ..grid import Grid
from ..scene import Light
from .atlas import Atlas
from .declare import VCT_FLUX, VCT_PYRAMID, VOX_PROJECTED, PassDecl
from .vct_inject import DIRECTIONS

_GRID = (Var("dims", "ivec3"),)
# Half floats: the cone gathers read half the bytes (a 6-cone gather at 1080p on an H100: 27 -> 13 ms;
# benchmarks/gpu). Their range ends at 65504, so the pyramid holds radiance x radiance_scale(), which maps
# a bound no cell's radiance can reach to HALF_BOUND; the cone tracer divides it out.
PYRAMID_FORMAT = "RGBA16F"
HALF_BOUND = 2.0**14
# level0 clamps to this (twice HALF_BOUND, below 65504): reached only by later bounces' gathered light,
# whose bound is not proven (radiance_scale), never by the first bounce's; it keeps the pyramid finite.
HALF_CLAMP = 2.0**15


DECL = PassDecl("vct_pyramid", "solve", (VCT_FLUX, VOX_PROJECTED), (VCT_PYRAMID,),
                "level 0 from the flux, the levels above by opacity compositing")


def _level0_spec(add: bool, isotropic: bool) -> ShaderSpec:
    defines = (("ADD", "1"),) if add else ()
    defines += (("ISOTROPIC", "1"),) if isotropic else ()
    return ShaderSpec(
        name=f"vct_level0{'_add' if add else ''}{'_iso' if isotropic else ''}",
        compute="vct/level0.comp.glsl",
        local_size=(4, 4, 4),
        samplers=(*(Sampler(f"flux_{d}", "2D") for d in DIRECTIONS), Sampler("vox_projected", "3D"),
                  *((Sampler(f"add_{d}", "3D") for d in DIRECTIONS) if add else ())),
        images=tuple(Image(f"pyr_{d}", "3D", PYRAMID_FORMAT) for d in DIRECTIONS),
        uniforms=(*_GRID, Var("cell_size", "float"), Var("tiles_x", "int"), Var("atlas_weight", "float"),
                  Var("radiance_scale", "float"), Var("half_clamp", "float")),
        defines=defines,
    )


LEVEL0 = {(add, iso): _level0_spec(add, iso) for add in (False, True) for iso in (False, True)}

DOWNSAMPLE = ShaderSpec(
    name="vct_downsample",
    compute="vct/downsample.comp.glsl",
    local_size=(4, 4, 4),
    samplers=tuple(Sampler(f"src_{d}", "3D") for d in DIRECTIONS),
    images=tuple(Image(f"pyr_{d}", "3D", PYRAMID_FORMAT) for d in DIRECTIONS),
    uniforms=(*_GRID, Var("level", "int")),
)

ACCUMULATE = ShaderSpec(
    name="vct_accumulate",
    compute="vct/accumulate.comp.glsl",
    local_size=(4, 4, 4),
    samplers=tuple(Sampler(f"next_{d}", "3D") for d in DIRECTIONS),
    images=tuple(Image(f"sum_{d}", "3D", access="read_write") for d in DIRECTIONS),
    uniforms=(*_GRID, Var("first", "int")),
)


def light_power_bound_w(light: Light, bounds_m: tuple[np.ndarray, np.ndarray]) -> float:
    """At least the power (W, brightest channel) `light` sends into the bounds: a point, spot or area light
    emits power_w in all (a spot masks a point light's intensity); a sun's RSM covers the bounds'
    projection, at most their diagonal squared, at `sun_strength` W/m^2."""
    brightest = max(float(np.max(light.color)), 0.0)
    if light.kind == "SUN":
        lo, hi = (np.asarray(b, np.float64) for b in bounds_m)
        return brightest * max(light.sun_strength, 0.0) * float(np.sum((hi - lo) ** 2))
    return brightest * max(light.power_w, 0.0)


def radiance_scale(lights: list[Light], bounds_m, cell_size_m: float, bounces: int, albedo_max: float) -> float:
    """What the pyramid multiplies radiance by so that half floats hold it: HALF_BOUND / (a bound on any
    cell's premultiplied radiance). A cell's colour is its VPLs' flux / (pi h^2) (level0.comp.glsl), and
    the flux of all VPLs together is at most the lights' power P times the largest albedo a (the flux
    cap never adds); bounce n reflects at most a^n P. So colour <= P (a + .. + a^N) / (pi h^2), a >= 1.
    Radiance as small as 4e-9 x the bound keeps half floats' 11 significant bits (2^-14 / HALF_BOUND)."""
    a = max(1.0, float(albedo_max))
    power = sum(light_power_bound_w(light, bounds_m) for light in lights)
    bound = power * sum(a**n for n in range(1, bounces + 1)) / (math.pi * cell_size_m**2)
    return HALF_BOUND / bound if bound > 0.0 and math.isfinite(bound) else 1.0


def level_dims(dims: tuple[int, int, int], level: int) -> tuple[int, int, int]:
    return tuple(-(-d // (1 << level)) for d in dims)


def level_count(dims: tuple[int, int, int]) -> int:
    """Levels down to one cell along the longest axis."""
    return 1 + math.ceil(math.log2(max(dims))) if max(dims) > 1 else 1


def level_offset(dims: tuple[int, int, int], level: int) -> int:
    """x offset of level `level` (pyramid.glsl): 2P - 2P / 2^level, P = dims.x up to a power of two."""
    two_p = 2 * (1 << (dims[0] - 1).bit_length())
    return two_p - (two_p >> level)


def texture_size(dims: tuple[int, int, int]) -> tuple[int, int, int]:
    """The pyramid textures' size: every level side by side along x (2P texels wide)."""
    return (2 * (1 << (dims[0] - 1).bit_length()), dims[1], dims[2])


def named(textures: dict, prefix: str) -> dict:
    """A direction-keyed set as the shader names it: {"px": t} -> {"<prefix>_px": t}."""
    return {f"{prefix}_{d}": textures[d] for d in DIRECTIONS}


def direction_textures(backend: Backend, size: tuple[int, ...]) -> dict:
    return {d: backend.texture(size) for d in DIRECTIONS}


def pyramid_textures(backend: Backend, grid: Grid) -> dict:
    return {d: backend.texture(texture_size(grid.dims), PYRAMID_FORMAT) for d in DIRECTIONS}


def level0(backend: Backend, flux: dict, vox_projected, pyramid: dict, grid: Grid, atlas: Atlas,
           scale: float, atlas_weight: float = 1.0, add: dict | None = None, isotropic: bool = False) -> None:
    """Write level 0 of `pyramid`: atlas_weight x the injected flux as radiance, plus `add` (level-0
    colours of later bounces) when given, times `scale` (radiance_scale)."""
    spec = LEVEL0[(add is not None, isotropic)]
    samplers = {**named(flux, "flux"), "vox_projected": vox_projected, **(named(add, "add") if add else {})}
    backend.dispatch(backend.program(spec), group_count(grid.dims, spec.local_size),
                     uniforms={"dims": grid.dims, "cell_size": grid.cell_size_m, "tiles_x": atlas.tiles_x,
                               "atlas_weight": atlas_weight, "radiance_scale": scale, "half_clamp": HALF_CLAMP},
                     samplers=samplers, images=named(pyramid, "pyr"))


def downsample(backend: Backend, pyramid: dict, grid: Grid) -> None:
    """Levels 1.. from level 0, in place."""
    prog = backend.program(DOWNSAMPLE)
    for level in range(1, level_count(grid.dims)):
        backend.dispatch(prog, group_count(level_dims(grid.dims, level), DOWNSAMPLE.local_size),
                         uniforms={"dims": grid.dims, "level": level}, samplers=named(pyramid, "src"),
                         images=named(pyramid, "pyr"))


def accumulate(backend: Backend, total: dict, bounce: dict, grid: Grid, first: bool) -> None:
    """total = bounce if first else total + bounce (level-0 colour sets of the grid's dims)."""
    backend.dispatch(backend.program(ACCUMULATE), group_count(grid.dims, ACCUMULATE.local_size),
                     uniforms={"dims": grid.dims, "first": int(first)}, samplers=named(bounce, "next"),
                     images=named(total, "sum"))
