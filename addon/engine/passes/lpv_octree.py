"""LPV octree (`lpv --variant octree`, paper 002, Olovsson): the grid as the finest level of a mip chain
of grids, each twice the cell of the one below, propagated level by level and merged coarse to fine.

Per update (LpvMethod.fill_octree, LpvMethod.propagate): every coarser level gets its source, either its
own injection of the VPLs (lpv_inject into its own atlas, `injects`) or level 0's source summed down the
chain (`downsample`: a coarse cell emits what its 2 x 2 x 2 children emit, lpv_far_field.source's
shader; the paper's way, and every later bounce's); every level runs its steps (`steps`) of the improved
transport (lpv_propagate), the finest LpvConfig.octree_blocked_levels through their own geometry volume
(built once per voxelization: the level below's projected areas summed / 4 and offsets averaged,
lpv_far_field.voxels, then lpv_propagate.blocking); then `merge` folds the levels from the coarsest down
into level 0's accumulation, which the ordinary lookup reads. A level of cell 2^i h
carries light 2^i cells per step, so k steps reach k 2^i cells: the finest levels resolve the light
near its sources, the coarsest carry it across the scene.

Two merges (LpvConfig.octree_merge):
- "index", the paper's: every level accumulates all k steps, and the merge keeps per cell the finest
  level holding light, with an epsilon and a blend (lpv_octree_reference.py derives it): M_i = w A_i +
  (1 - w) U, U = the merged level i + 1 read at level i's centres (trilinear x 1/4: the same reading at
  cell h from acc_{i+1} at 2h), w = clamp(rho / eps - 1, 0, 1), rho the ratio of their light. eps -> 0
  is the paper's "finest level with non-zero light".
- "time": the levels split the light by its time of flight, as the far field splits it between two
  grids (lpv_far_field): level i's step s moves light 2^i fine cells, so it stands for fine time t = s
  2^i, and it is accumulated with `time_share` = g_i(t) - g_{i-1}(t), g_i the far field's fine share
  with K_i = k 2^i near steps (1 up to K_i / 2, 0 from K_i; g_{-1} = 0, the coarsest level's g = 1).
  The shares telescope: at every time the levels count the light once in sum, and the merge adds them
  (M_i = A_i + U). A coarse level counts only flights longer than k 2^(i-2) fine steps, so the light
  a coarse cell straddling a wall lets through in its first steps is not counted; what it lets through
  later is (thin-wall, docs/LPV.md "Octree").

Inputs / outputs of `merge`: the merged coarser accumulation (keys acc_r/g/b; RGBA32F 3D, L1 SH, W/sr x
cells, as lpv_propagate accumulates) -> the finer accumulation `acc_r/g/b` (read-write, every cell).
"""

from __future__ import annotations

from ..backends.base import Backend, Image, Sampler, ShaderSpec, Var, group_count
from ..grid import Grid
from . import lpv_far_field
from .declare import LPV_ACCUMULATED, LPV_BLOCKING, LPV_SNAPSHOT, PassDecl

MERGE = ShaderSpec(
    name="lpv_octree_merge",
    compute="lpv/octree_merge.comp.glsl",
    local_size=(4, 4, 4),
    samplers=tuple(Sampler(f"coarse_{c}", "3D") for c in "rgb"),
    images=tuple(Image(f"acc_{c}", "3D", "RGBA32F", "read_write") for c in "rgb"),
    uniforms=(Var("dims", "ivec3"), Var("coarse_dims", "ivec3"), Var("epsilon", "float")),
)

DECL = PassDecl("lpv_octree", "solve", (LPV_SNAPSHOT, LPV_BLOCKING, LPV_ACCUMULATED), (LPV_SNAPSHOT, LPV_ACCUMULATED),
                "the mip chain's sources (timed in lpv_inject), its levels merged coarse to fine (in lpv_propagate)")


def injects(merge_mode: str) -> bool:
    """Whether every level gets the VPLs injected itself on the first bounce (the time merge, as the far
    field does: a VPL lands in the coarse cell in front of its surface, so a coarse cell straddling a
    sunlit roof does not hold the roof's light inside the room) or summed down from level 0 (the
    paper's downsampling; later bounces always sum down the re-injected light)."""
    return merge_mode == "time"


def level_grids(grid: Grid, levels: int) -> list[Grid]:
    """Levels 1 .. levels-1 above `grid` (level 0): each the one below's origin, twice its cell and
    ceil(dims / 2) cells (lpv_far_field.grid_for), so cell j holds cells 2j and 2j + 1 below it."""
    out = [grid]
    for _ in range(levels - 1):
        out.append(lpv_far_field.grid_for(out[-1]))
    return out[1:]


def time_share(level: int, step: int, iterations: int, levels: int) -> float:
    """The "time" merge's share of level `level`'s propagation step `step` (1-based), k = `iterations`
    steps per level, `levels` levels (module docstring)."""
    fine_time = step * 2**level

    def finer_share(lv: int) -> float:  # the share levels 0 .. lv count together at this time
        if lv < 0:
            return 0.0
        return 1.0 if lv == levels - 1 else lpv_far_field.fine_weight(fine_time, iterations * 2**lv)

    return finer_share(level) - finer_share(level - 1)


def steps(level: int, iterations: int, levels: int, merge_mode: str, coarsest_span: int) -> int:
    """Propagation steps of `level`: k with the "index" merge; with "time" each finer level's last step
    with a share is k - 1, and the coarsest carries the light until it has crossed its grid (at least
    k, its Manhattan span `coarsest_span`)."""
    if merge_mode == "index":
        return iterations
    if level == levels - 1:
        return max(iterations, coarsest_span)
    return max(1, iterations - 1)


def downsample(backend: Backend, fine_snapshot: dict, fine: Grid, coarse_snapshot: dict, coarse: Grid) -> None:
    """coarse_snapshot (keys sh_r/g/b) = per coarse cell the sum of its children in fine_snapshot."""
    lpv_far_field.source(backend, fine_snapshot, fine, coarse_snapshot, coarse)


def merge(backend: Backend, coarse_acc: dict, coarse: Grid, fine_acc: dict, fine: Grid, merge_mode: str,
          epsilon: float) -> None:
    """fine_acc (keys acc_r/g/b) := with "index", the blend of itself and coarse_acc (keys acc_r/g/b,
    already merged) by the index rule with `epsilon`; with "time", itself + coarse_acc read at its
    centres (lpv_far_field.add's shader)."""
    if merge_mode == "time":
        lpv_far_field.add(backend, coarse_acc, coarse, fine_acc, fine)
        return
    backend.dispatch(backend.program(MERGE), group_count(fine.dims, MERGE.local_size),
                     uniforms={"dims": fine.dims, "coarse_dims": coarse.dims, "epsilon": float(epsilon)},
                     samplers={f"coarse_{c}": coarse_acc[f"acc_{c}"] for c in "rgb"}, images=fine_acc)
