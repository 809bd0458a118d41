"""VCT radiance pyramid: level 0 from the injected flux, the levels above by opacity compositing.

Every set of six textures is a dict keyed by direction ("px" .. "nz", vct_inject.DIRECTIONS).
Layout (gpu_shaders/vct/pyramid.glsl): six RGBA32F 3D textures, one per axis direction t of travel,
every level side by side along x; level l has dims ceil(dims / 2^l) and is sampled quadrilinearly by
hand (cone.glsl). rgb = premultiplied radiance (W/m^2/sr over the cell's
cross-section), a = opacity, as met by a ray travelling along -t.

Passes:
- level0: flux atlas (vct_inject) x atlas_weight / (pi h^2) [+ later bounces' colours `add_*`] ->
  level 0 colours; opacity min(1, projected area / h^2) from the voxelizer's `vox_projected`.
- downsample (one dispatch per level): 2x2x2 children composited front to back along t, the four
  pairs averaged (no second premultiplication).
- accumulate: sum_* = next_* (first) or sum_* + next_* (the bounces after the first, level 0).
"""

from __future__ import annotations

import math

from ..backends.base import Backend, Image, Sampler, ShaderSpec, Var, group_count
from ..grid import Grid
from .atlas import Atlas
from .vct_inject import DIRECTIONS

_GRID = (Var("dims", "ivec3"),)
# Full floats. Half floats would halve the gather's bytes (six 64^3 pyramids are 50 MB in fp32, an
# H100's whole L2) with no change in cornell's error, but they overflow at 65504 W/m^2/sr: the hard
# case that scales a light's power by 1e6 then turned to Inf. Half needs an exposure scale first.
PYRAMID_FORMAT = "RGBA32F"


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
        uniforms=(*_GRID, Var("cell_size", "float"), Var("tiles_x", "int"), Var("atlas_weight", "float")),
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
           atlas_weight: float = 1.0, add: dict | None = None, isotropic: bool = False) -> None:
    """Write level 0 of `pyramid`: atlas_weight x the injected flux as radiance, plus `add` (level-0
    colours of later bounces) when given."""
    spec = LEVEL0[(add is not None, isotropic)]
    samplers = {**named(flux, "flux"), "vox_projected": vox_projected, **(named(add, "add") if add else {})}
    backend.dispatch(backend.program(spec), group_count(grid.dims, spec.local_size),
                     uniforms={"dims": grid.dims, "cell_size": grid.cell_size_m, "tiles_x": atlas.tiles_x,
                               "atlas_weight": atlas_weight},
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
