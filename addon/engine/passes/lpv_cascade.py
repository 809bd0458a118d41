"""LPV cascades: nested grids of one cell count, each twice the cell size of the next finer one, the
finest around the camera, the coarsest fitted to the scene (docs/LPV.md, "Cascades"; seeds 002).

`place` puts the grids (pure numpy). `inflow` adds to a finer cascade's injected snapshot the light
that enters it through its interior faces from its parent, already propagated. `blend_weight` is the
numpy twin of the lookup's cascade weight (lookup.comp.glsl, CASCADE).

Inputs of `inflow`: the parent's accumulation `acc_r/g/b` and its injected snapshot `sh_r/g/b` (RGBA32F
3D, L1 SH of radiant intensity, W/sr per cell by direction of travel), the finer cascade's snapshot
`sh_r/g/b` (added to in its face cells). Portable: one compute invocation per finer cell, gather form.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..backends.base import Backend, Image, Sampler, ShaderSpec, Var, group_count
from ..grid import Grid
from . import lpv_propagate
from .declare import LPV_ACCUMULATED, LPV_SNAPSHOT, TRIANGLES, VOXELS, PassDecl

PAD_CELLS = 1.5  # Grid.fit's padding
# The lookup blends a cascade into its parent over BAND_CELLS of its cells, starting BAND_START_CELLS
# inside its interior faces: the outermost cells lack the inflow in their own accumulation (it is added
# to their source snapshot, which the improved variant does not accumulate), and trilinear filtering at
# less than 1.5 cells reads them.
BAND_START_CELLS = 2.0
BAND_CELLS = 4.0


@dataclass(frozen=True)
class Cascade:
    """A grid and, per axis, whether its low / high face lies strictly inside its parent (1) or on the
    parent's face (0: nothing coarser beyond it to blend to, or the coarsest cascade). `parent_offset`:
    its origin in parent cells (integers: faces are parent-cell aligned)."""

    grid: Grid
    interior_lo: tuple[int, int, int] = (0, 0, 0)
    interior_hi: tuple[int, int, int] = (0, 0, 0)
    parent_offset: tuple[int, int, int] = (0, 0, 0)


PLACE_DECL = PassDecl("lpv_place", "solve", (TRIANGLES,), VOXELS,
                      "finer cascades re-placed around the camera, re-voxelized where they moved")
INFLOW_DECL = PassDecl("lpv_inflow", "solve", (LPV_ACCUMULATED, LPV_SNAPSHOT), (LPV_SNAPSHOT,),
                       "a parent cascade's light entering a finer one (timed in lpv_inject)")


def _fitted(lo: np.ndarray, hi: np.ndarray, cell_m: float) -> Grid:
    """Grid.fit's layout at a given cell size: the bounds plus PAD_CELLS each side, centred."""
    dims = np.maximum(np.ceil(np.maximum(hi - lo, 1e-6) / cell_m + 2.0 * PAD_CELLS).astype(int), 1)
    return Grid((lo + hi) / 2.0 - dims * cell_m / 2.0, cell_m, tuple(int(d) for d in dims))


def place(lo, hi, camera_m, grid_cells: int, cascades: int, cell_size_m: float = 0.0) -> list[Cascade]:
    """The cascades, finest first. The coarsest is Grid.fit(lo, hi, grid_cells) (cascades = 1: today's
    single grid); each finer one halves the cell size and keeps its parent's extent on the axes where that
    takes at most grid_cells cells, and elsewhere takes grid_cells (rounded down to even) cells centred
    on the camera, snapped to parent cells and clamped into the parent (so the grids nest, and stay put
    while the camera moves within a parent cell). cell_size_m > 0 asks for that finest cell: the fewest
    cascades whose coarsest covers the scene at <= grid_cells per axis; where `cascades` cannot, the
    finest cell grows to Grid.fit's / 2^(cascades - 1), as with cell_size_m = 0."""
    lo, hi = np.asarray(lo, np.float64), np.asarray(hi, np.float64)
    camera_m = np.asarray(camera_m, np.float64)
    top, levels = Grid.fit(lo, hi, max_cells=grid_cells), cascades
    if cell_size_m > 0.0:
        for k in range(cascades):
            grid = _fitted(lo, hi, cell_size_m * 2.0**k)
            if max(grid.dims) <= grid_cells:
                top, levels = grid, k + 1
                break
    chain = [Cascade(top)]
    n_trunc = grid_cells - grid_cells % 2
    for _ in range(levels - 1):
        parent = chain[-1].grid
        h = parent.cell_size_m / 2.0
        axes = []  # per axis: (cells, origin in parent cells, low face interior, high face interior)
        for a in range(3):
            j_lo, j_hi = 0, parent.dims[a]
            if 2 * (j_hi - j_lo) <= grid_cells:
                j, j_end = j_lo, j_hi
            else:
                j = int(np.clip(np.round((camera_m[a] - parent.origin_m[a]) / parent.cell_size_m - n_trunc / 4.0),
                                j_lo, j_hi - n_trunc // 2))
                j_end = j + n_trunc // 2
            # A face is interior where the parent goes on beyond it, or where it lies on an
            # interior face of the parent (then the parent blends out there and so must this one).
            interior_lo = j > j_lo or (j == 0 and chain[-1].interior_lo[a])
            interior_hi = j_end < j_hi or (j_end == parent.dims[a] and chain[-1].interior_hi[a])
            axes.append((2 * (j_end - j), j, int(interior_lo), int(interior_hi)))
        dims, offset, int_lo, int_hi = (tuple(int(v) for v in col) for col in zip(*axes, strict=True))
        grid = Grid(parent.origin_m + np.array(offset) * parent.cell_size_m, h, dims)
        chain.append(Cascade(grid, int_lo, int_hi, offset))
    return chain[::-1]


def blend_weight(cascade: Cascade, g: np.ndarray) -> float:
    """The lookup's weight of `cascade` against its parent at grid coordinates g (cells): 0 outside and
    within BAND_START_CELLS of an interior face, rising linearly to 1 over BAND_CELLS; faces on the
    parent's faces do not count. The parent gets 1 - weight, so the weights of a chain sum to 1."""
    d = np.inf
    for a in range(3):
        if cascade.interior_lo[a]:
            d = min(d, g[a])
        if cascade.interior_hi[a]:
            d = min(d, cascade.grid.dims[a] - g[a])
    return float(np.clip((d - BAND_START_CELLS) / BAND_CELLS, 0.0, 1.0))


def _inflow_spec(variant: str) -> ShaderSpec:
    return ShaderSpec(
        name=f"lpv_inflow_{variant}",
        compute="lpv/inflow.comp.glsl",
        local_size=(4, 4, 4),
        samplers=tuple(Sampler(f"parent_acc_{c}", "3D") for c in "rgb") + tuple(
            Sampler(f"parent_s0_{c}", "3D") for c in "rgb"),
        images=tuple(Image(f"sh_{c}", "3D", "RGBA32F", "read_write") for c in "rgb"),
        uniforms=(Var("dims", "ivec3"), Var("interior_lo", "ivec3"), Var("interior_hi", "ivec3"),
                  Var("parent_offset", "ivec3"), Var("parent_dims", "ivec3"), Var("inv_step_weight", "float"),
                  Var("source_keep", "float"),
                  Var("m_cross", "float"), Var("m_along", "float"), Var("m_side", "float")),
        defines=(("IMPROVED", "1"),) if variant == "improved" else (),
    )


INFLOW = {v: _inflow_spec(v) for v in ("classic", "improved")}


def inflow(backend: Backend, cascade: Cascade, snapshot: dict, parent: Grid, parent_acc: dict, parent_s0: dict,
           variant: str) -> None:
    """snapshot (keys sh_r/g/b, the finer cascade's injection) += the light entering through its interior
    faces from the parent's accumulation (keys acc_r/g/b) and injected snapshot (keys sh_r/g/b)."""
    spec = INFLOW[variant]
    source_weight, step_weight = lpv_propagate.weights(variant)
    c = lpv_propagate.improved_constants() if variant == "improved" else {"m_cross": 0.0, "m_along": 0.0,
                                                                           "m_side": 0.0}
    samplers = {**{f"parent_acc_{ch}": parent_acc[f"acc_{ch}"] for ch in "rgb"},
                **{f"parent_s0_{ch}": parent_s0[f"sh_{ch}"] for ch in "rgb"}}
    uniforms = {"dims": cascade.grid.dims, "interior_lo": cascade.interior_lo, "interior_hi": cascade.interior_hi,
                "parent_offset": cascade.parent_offset, "parent_dims": parent.dims,
                "inv_step_weight": 1.0 / step_weight, "source_keep": 1.0 - source_weight / step_weight, **c}
    backend.dispatch(backend.program(spec), group_count(cascade.grid.dims, spec.local_size), uniforms=uniforms,
                     samplers=samplers, images=snapshot)
