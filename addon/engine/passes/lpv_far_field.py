"""LPV far field: light beyond a grid's near steps carried on a grid of twice the cell size (docs/LPV.md, "Far
field"; the hierarchical propagation of seeds 002, with two levels).

The improved transport moves light one axis step per step, so a grid needs its Manhattan span of steps. Here
the fine grid runs only its first `near_steps` K and a coarse grid (`grid_for`: same origin, cell 2h,
ceil(dims / 2) cells; its own injection, and a geometry volume summed from the fine grid's voxels by
`voxels`) its whole span, half as many steps for the same distance at 1/8 of the cells: ~4x less propagation
work at 32 cells, and less error on every benchmark scene but thin-wall (conference equal), also with the
level corrected (measured, docs/LPV.md; in open space both read the same on-axis excess, so the gain is the
per-step artefacts of walls, not of free flight). Each accumulates a share of its steps: the fine grid's
step s with `fine_weight(s)` (1 up to K/2, falling linearly to 0 at K), the coarse grid's step s' with 1 -
fine_weight(2 s'). The shares are by time of flight: a coarse step moves light two fine cells, so coarse
step s' stands for fine steps 2 s' and 2 s' + 1, and the light is counted once in sum at every time; the
switch is spread over K/2 .. K steps instead of one step. (Light does not arrive one cell per step: on an
axis a point source's light passes r cells out over steps ~1.3 r .. 2.5 r, peaking near 1.9 r.) `add` adds
the coarse accumulation to the fine one; everything downstream (lookup, re-injection, cascades' inflow,
volume bakes) reads the sum.

Inputs / outputs: `add`: the coarse accumulation `far_r/g/b` (RGBA32F 3D, L1 SH, as the propagation
accumulates) -> the fine accumulation `acc_r/g/b` (read-write). `source`: a fine snapshot `fine_r/g/b` ->
the coarse snapshot `sh_r/g/b` (written in every cell), for bounces after the first. `voxels`: the fine
voxelizer's `vox_projected` and `vox_offset` -> the coarse grid's (new textures; written in every cell):
projected areas summed / 4, offsets averaged by projected area (far_field_voxels.comp.glsl).
"""

from __future__ import annotations

from ..backends.base import Backend, Image, Sampler, ShaderSpec, Var, group_count
from ..grid import Grid
from .declare import LPV_ACCUMULATED, LPV_SNAPSHOT, VOX_OFFSET, VOX_PROJECTED, PassDecl

# Below a coarse grid of 16 cells along the longest side the far field resolves too little of a scene
# (16-cell grids with an 8-cell far field, measured: thin-wall rel_rmse_8 0.50 against 0.25 on one grid,
# window-room 1.03 against 0.90).
MIN_GRID_CELLS = 32

ADD = ShaderSpec(
    name="lpv_far_field_add",
    compute="lpv/far_field_add.comp.glsl",
    local_size=(4, 4, 4),
    samplers=tuple(Sampler(f"far_{c}", "3D") for c in "rgb"),
    images=tuple(Image(f"acc_{c}", "3D", "RGBA32F", "read_write") for c in "rgb"),
    uniforms=(Var("dims", "ivec3"), Var("coarse_dims", "ivec3")),
)

SOURCE = ShaderSpec(
    name="lpv_far_field_source",
    compute="lpv/far_field_source.comp.glsl",
    local_size=(4, 4, 4),
    samplers=tuple(Sampler(f"fine_{c}", "3D") for c in "rgb"),
    images=tuple(Image(f"sh_{c}", "3D", "RGBA32F", "write") for c in "rgb"),
    uniforms=(Var("dims", "ivec3"), Var("fine_dims", "ivec3"), Var("fine_shift", "ivec3")),
)

VOXELS = ShaderSpec(
    name="lpv_far_field_voxels",
    compute="lpv/far_field_voxels.comp.glsl",
    local_size=(4, 4, 4),
    samplers=(Sampler("fine_projected", "3D"), Sampler("fine_offset", "3D")),
    images=(Image("vox_projected", "3D", "RGBA32F", "write"), Image("vox_offset", "3D", "RGBA32F", "write")),
    uniforms=(Var("dims", "ivec3"), Var("fine_dims", "ivec3")),
)


DECL = PassDecl("lpv_far_field", "solve", (LPV_SNAPSHOT, VOX_PROJECTED, VOX_OFFSET), (LPV_ACCUMULATED,),
                "light beyond the near steps carried on a grid of twice the cell (timed in lpv_propagate)")


def grid_for(fine: Grid) -> Grid:
    """The far-field grid: the fine grid's origin, twice its cell, ceil(dims / 2) cells (it covers the
    fine grid, and up to one fine cell more on odd axes); coarse cell j holds fine cells 2j and 2j + 1."""
    return Grid(fine.origin_m, 2.0 * fine.cell_size_m, tuple((d + 1) // 2 for d in fine.dims))


def fine_weight(step: int, near_steps: int) -> float:
    """The share of the fine grid's propagation step `step` (1-based) that is accumulated."""
    return min(1.0, max(0.0, (near_steps - step) / (near_steps / 2.0)))


def coarse_weight(step: int, near_steps: int) -> float:
    """The share of the coarse grid's step `step` (1-based): the rest of what the fine grid leaves out at
    the same time of flight, fine step 2 * step."""
    return 1.0 - fine_weight(2 * step, near_steps)


def add(backend: Backend, coarse_acc: dict, coarse: Grid, fine_acc: dict, fine: Grid) -> None:
    """fine_acc (keys acc_r/g/b) += 1/4 x coarse_acc (keys acc_r/g/b) trilinear at each fine cell's centre."""
    backend.dispatch(backend.program(ADD), group_count(fine.dims, ADD.local_size),
                     uniforms={"dims": fine.dims, "coarse_dims": coarse.dims},
                     samplers={f"far_{c}": coarse_acc[f"acc_{c}"] for c in "rgb"}, images=fine_acc)


def source(backend: Backend, fine_snapshot: dict, fine: Grid, coarse_snapshot: dict, coarse: Grid,
           fine_shift: tuple[int, int, int] = (0, 0, 0)) -> None:
    """coarse_snapshot (keys sh_r/g/b) = per coarse cell the sum of its fine cells in fine_snapshot: coarse
    cell j holds fine cells 2j - fine_shift .. 2j - fine_shift + 1 per axis (0: `grid_for`'s)."""
    backend.dispatch(backend.program(SOURCE), group_count(coarse.dims, SOURCE.local_size),
                     uniforms={"dims": coarse.dims, "fine_dims": fine.dims, "fine_shift": tuple(fine_shift)},
                     samplers={f"fine_{c}": fine_snapshot[f"sh_{c}"] for c in "rgb"}, images=coarse_snapshot)


def voxels(backend: Backend, fine_voxels: dict, fine: Grid, coarse: Grid, out: dict | None = None) -> dict:
    """The coarse grid's vox_projected and vox_offset (`out`'s textures, or new ones) from the fine
    voxelizer's: what lpv_propagate.blocking reads."""
    out = out or {k: backend.texture(coarse.dims) for k in ("vox_projected", "vox_offset")}
    backend.dispatch(backend.program(VOXELS), group_count(coarse.dims, VOXELS.local_size),
                     uniforms={"dims": coarse.dims, "fine_dims": fine.dims},
                     samplers={"fine_projected": fine_voxels["vox_projected"],
                               "fine_offset": fine_voxels["vox_offset"]},
                     images=out)
    return out
