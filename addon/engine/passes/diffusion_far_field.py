"""Diffusion far field: the light still in flight after the fine grid's near steps carried on to its end on
a grid of twice the cell size (docs/DIFFUSION.md, "Far field"; lpv_far_field does the same for lpv).

A bounce's light needs twice the grid's span of steps to settle (DiffusionConfig.span_multiple). Here the
fine grid runs only its first `near_steps` K; what is still in flight then is summed into a far grid
(`grid_for`: cell 2h, its own voxelization and cells, aligned by `best_shift`), which runs the rest of
the bounce in half as many steps (a far step moves light two fine cells) at 1/8 of the cells. Every watt
is absorbed on one grid or the other, or is still in flight at the end: nothing is counted twice or
dropped at the hand-over.

`hand_over`: the fine light in flight summed per far cell (lpv_far_field.source: radiant intensity adds),
per emitter class and bounce; a far cell on the edge where a wall meets a floor is walled in by occupied
cells, and the light in it, which could not leave, is moved to the neighbours it can leave from
(far_field_move.comp.glsl). The far grid keeps what it absorbs by the face the light came through
(diffusion_propagate.faces): its cells are too coarse to have one plane (a cell holding a wall and the
floor of the room behind it has a normal between the two, whose sides would mix the rooms). `add`
shares each face's flux onto the fine planes' sides, which the light's direction sorts as a fine step
would, by their absorption on that axis and the far cells' trilinear tents, so the far light is smooth
across far cells and each far cell gives out exactly what it absorbed (`weights`, once per voxelization:
each far cell's share denominators, far_field_weights.comp.glsl; far_field_add.comp.glsl). Everything
downstream (the class and bounce sums, the next bounce's emitters, the lookup) reads the sum.
Twins: diffusion_reference.far_move_enclosed, step_by_face, far_weights, far_add.
"""

from __future__ import annotations

import functools
from typing import NamedTuple

import numpy as np

from ..backends.base import Backend, Image, Sampler, ShaderSpec, Var, group_count
from ..grid import Grid
from . import lpv_far_field
from .declare import PassDecl
from .diffusion_cells import CELL_BLOCK, CELL_NORMAL
from .diffusion_inject import SNAPSHOT
from .diffusion_propagate import ABSORBED, FACE_TEXELS

# The fine grid's longest side from which the far field runs: its 16-cell far grid is the coarsest that
# resolves a room (one 16-cell grid: window-room rel_rmse_8 1.160 against 0.366 at 32, docs/DIFFUSION.md).
MIN_GRID_CELLS = 32

@functools.cache
def move_spec(cone: int | None) -> ShaderSpec:
    """The enclosed cells' move; a cone field's (`cone`) moves its light along the cone's axis."""
    return ShaderSpec(
        name="diffusion_far_field_move" + ("" if cone is None else f"_cone_field_{cone}"),
        compute="diffusion/far_field_move.comp.glsl",
        local_size=(4, 4, 4),
        samplers=(*(Sampler(f"src_{c}", "3D") for c in "rgb"), Sampler("cell_block", "3D")),
        images=tuple(Image(f"sh_{c}", "3D", "RGBA32F", "write") for c in "rgb"),
        uniforms=(Var("dims", "ivec3"),),
        defines=() if cone is None else (("CONE", str(cone)),),
    )

WEIGHTS = ShaderSpec(
    name="diffusion_far_field_weights",
    compute="diffusion/far_field_weights.comp.glsl",
    local_size=(4, 4, 4),
    samplers=(Sampler("far_block", "3D"), Sampler("cell_normal", "3D"), Sampler("cell_block", "3D")),
    images=(Image("weight_0", "3D", "RGBA32F", "write"), Image("weight_1", "3D", "RGBA32F", "write")),
    uniforms=(Var("dims", "ivec3"), Var("fine_dims", "ivec3"), Var("fine_shift", "ivec3")),
)

ADD = ShaderSpec(
    name="diffusion_far_field_add",
    compute="diffusion/far_field_add.comp.glsl",
    local_size=(4, 4, 4),
    samplers=(*(Sampler(f"far_{i}", "3D") for i in range(FACE_TEXELS)), Sampler("weight_0", "3D"),
              Sampler("weight_1", "3D"), Sampler("cell_normal", "3D"), Sampler("cell_block", "3D")),
    images=(Image("acc_plus", "3D", "RGBA32F", "read_write"), Image("acc_minus", "3D", "RGBA32F", "read_write")),
    uniforms=(Var("dims", "ivec3"), Var("far_dims", "ivec3"), Var("fine_shift", "ivec3")),
)

DECL = PassDecl("diffusion_far_field", "solve", (SNAPSHOT, ABSORBED, CELL_NORMAL, CELL_BLOCK), (ABSORBED,),
                "the light in flight after the near steps carried on a grid of twice the cell, its absorbed "
                "flux shared back onto the fine sides")


class FarGrid(NamedTuple):
    """A far grid: twice the fine grid's cell, starting `shift` fine cells (0 or 1 per axis, x y z) before
    it, so far cell j holds fine cells 2j - shift and 2j - shift + 1 on each axis."""

    grid: Grid
    shift: tuple[int, int, int]


def grid_for(fine: Grid, shift: tuple[int, int, int] = (0, 0, 0)) -> FarGrid:
    """The far grid of `fine` starting `shift` fine cells before it; it covers the fine grid."""
    s = np.array(shift)
    dims = tuple(int(d) for d in (np.array(fine.dims) + s + 1) // 2)
    return FarGrid(Grid(np.asarray(fine.origin_m) - s * fine.cell_size_m, 2.0 * fine.cell_size_m, dims),
                   tuple(int(v) for v in shift))


def best_shift(occupied: np.ndarray) -> tuple[int, int, int]:
    """The shift (x, y, z) whose far grid has the fewest cells holding a fine occupied cell, of the 8
    (ties: the first in x, y, z order from (0, 0, 0)). Occupancy is binary in the far grid as in the fine
    one, so a wall two fine cells thick across a far cells' border fills two far cells: every wall of a
    room then stands a far cell into it, and a room of 12 fine cells becomes one of 5 far cells (the
    thin-wall scene at 32 cells: 1046 far cells occupied at shift 0, 528 at (1, 1, 1)). `occupied` is
    (z, y, x) bool."""
    best, fewest = (0, 0, 0), None
    for shift in np.ndindex(2, 2, 2):
        padded = np.pad(occupied, [(shift[2], 0), (shift[1], 0), (shift[0], 0)])
        padded = np.pad(padded, [(0, n % 2) for n in padded.shape])
        z, y, x = padded.shape
        count = int(padded.reshape(z // 2, 2, y // 2, 2, x // 2, 2).any(axis=(1, 3, 5)).sum())
        if fewest is None or count < fewest:
            best, fewest = tuple(int(v) for v in shift), count
    return best


def near_steps(configured: int, steps: int) -> int:
    """The fine grid's steps K with a far field, of a bounce's `steps`: `configured`, or (0) half of them
    (the grid's span at span_multiple 2), at least 1 and at most `steps`."""
    return max(1, min(configured or steps // 2, steps))


def hand_over(backend: Backend, snapshot: dict, fine: Grid, far_snapshots: list, far_cells: dict, far: FarGrid,
              cone: int | None = None) -> None:
    """far_snapshots[0] (sh_r/g/b) := the far grid's starting light: the fine `snapshot` (the light in
    flight; `cone`: that cone field's) summed per far cell (lpv_far_field.source, into far_snapshots[1]),
    the light of enclosed far cells moved to their neighbours (far_field_move.comp.glsl)."""
    lpv_far_field.source(backend, snapshot, fine, far_snapshots[1], far.grid, far.shift)
    move = move_spec(cone)
    backend.dispatch(backend.program(move), group_count(far.grid.dims, move.local_size),
                     uniforms={"dims": far.grid.dims},
                     samplers={**{f"src_{c}": far_snapshots[1][f"sh_{c}"] for c in "rgb"},
                               "cell_block": far_cells["cell_block"]},
                     images=far_snapshots[0])


def weights(backend: Backend, far_cells: dict, far: FarGrid, cells: dict, fine: Grid, out: dict | None = None) -> dict:
    """The far cells' weights per face (weight_0 / weight_1, far_field_weights.comp.glsl): what their
    absorbed flux is shared out by; once per voxelization. `out`'s textures, or new ones."""
    out = out or {k: backend.texture(far.grid.dims) for k in ("weight_0", "weight_1")}
    backend.dispatch(backend.program(WEIGHTS), group_count(far.grid.dims, WEIGHTS.local_size),
                     uniforms={"dims": far.grid.dims, "fine_dims": fine.dims, "fine_shift": far.shift},
                     samplers={"far_block": far_cells["cell_block"], **cells}, images=out)
    return out


def add(backend: Backend, far_absorbed: dict, far_weights: dict, far: FarGrid, absorbed: dict, cells: dict,
        fine: Grid) -> None:
    """absorbed (the fine grid's flux_plus / flux_minus, W) += the far grid's absorbed flux per face
    (acc_0 .. acc_4, diffusion_propagate.faces) shared onto the fine sides by `far_weights` (`weights`)
    and the far cells' trilinear tents (far_field_add.comp.glsl)."""
    backend.dispatch(backend.program(ADD), group_count(fine.dims, ADD.local_size),
                     uniforms={"dims": fine.dims, "far_dims": far.grid.dims, "fine_shift": far.shift},
                     samplers={**{f"far_{i}": far_absorbed[f"acc_{i}"] for i in range(FACE_TEXELS)}, **far_weights,
                               **cells},
                     images={"acc_plus": absorbed["flux_plus"], "acc_minus": absorbed["flux_minus"]})
