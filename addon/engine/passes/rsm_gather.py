"""RSM indirect gather pass (Dachsbacher & Stamminger 2005, eq. 1 with a disk term), no visibility.

Inputs: G-buffer position and normal; one RSM face's position, normal (w = surfel area, m^2) and flux
(W). Uniforms: strata_per_side (VPLs per pixel = strata_per_side^2), the face's view-projection and
near_strata (near_strata^2 draws near the receiver's own texel in each of three squares, besides the
strata), seed, sample_index; with voxel visibility also the voxelizer's occupancy (`vox_albedo`,
a = occupancy) and its grid. Output: `indirect` (RGBA32F, camera resolution), accumulated over faces
and lights, in Cycles' Diffuse Indirect unit (indirect irradiance / pi). One bounce. See
gpu_shaders/rsm/gather.comp.glsl for the estimator.
"""

from __future__ import annotations

import math

import numpy as np

from ..backends.base import Backend, Image, Sampler, ShaderSpec, Var, group_count
from ..grid import Grid
from .declare import GBUF_NORMAL, GBUF_POSITION, INDIRECT, RSM, VOX_ALBEDO, PassDecl

_SAMPLERS = (Sampler("gbuf_position", "2D"), Sampler("gbuf_normal", "2D"), Sampler("rsm_position", "2D"),
             Sampler("rsm_normal", "2D"), Sampler("rsm_flux", "2D"))
_UNIFORMS = (Var("strata_per_side", "int"), Var("seed", "int"), Var("sample_index", "int"), Var("row_begin", "int"),
             Var("row_end", "int"), Var("rsm_view_projection", "mat4"), Var("near_strata", "int"))
# llvmpipe ends a shader invocation's loops after 65,535 iterations in total (FACTS.md); keep each
# dispatch's worst case below that. A GPU has no such cap; the split costs it a few dispatches.
MAX_LOOP_ITERATIONS = 60_000

SPEC = ShaderSpec(
    name="rsm_gather",
    compute="rsm/gather.comp.glsl",
    local_size=(8, 8, 1),
    samplers=_SAMPLERS,
    images=(Image("indirect", "2D", "RGBA32F", "read_write"),),
    uniforms=_UNIFORMS,
)

SPEC_VOXEL_VISIBILITY = ShaderSpec(
    name="rsm_gather_voxel_visibility",
    compute="rsm/gather.comp.glsl",
    local_size=(8, 8, 1),
    samplers=(*_SAMPLERS, Sampler("occupancy", "3D")),
    images=(Image("indirect", "2D", "RGBA32F", "read_write"),),
    uniforms=(*_UNIFORMS, Var("grid_origin", "vec3"), Var("cell_size", "float"), Var("grid_dims", "ivec3"),
              Var("offset_cells", "float")),
    defines=(("VOXEL_VISIBILITY", "1"),),
)


DECL = PassDecl("rsm_gather", "gather", (GBUF_POSITION, GBUF_NORMAL, *RSM, VOX_ALBEDO), (INDIRECT,),
                "one face's VPLs gathered at every pixel (voxel visibility: through the occupancy), added")


def strata_per_side(vpl_samples: int) -> int:
    """VPLs are drawn one per block of a k x k split of the RSM: k = floor(sqrt(samples)), at least 1."""
    return max(1, math.isqrt(vpl_samples))


def near_strata(vpl_samples: int) -> int:
    """Draws near the receiver (gather.comp.glsl, "Near draws"): near_strata^2 in each of three squares,
    about half a row of strata each (1 at 16 VPLs and fewer, 3 at 256: 27 draws beside the 256)."""
    return max(1, round(math.sqrt(strata_per_side(vpl_samples) / 2)))


def run(backend: Backend, gbuf: dict, rsm: dict, indirect, vpl_samples: int, seed: int, view_projection,
        occupancy=None, grid: Grid | None = None, offset_cells: float = 1.5, sample: int = 0) -> None:
    """Gather one RSM face (drawn through `view_projection`, the face's local-space 4 x 4) into
    `indirect`; pass the voxelizer's `vox_albedo` and grid for visibility. `seed` is the update's;
    `sample` the gather's index among those averaged since (DirectMethod.sample_index): the draws step
    along a low-discrepancy sequence with it."""
    spec = SPEC if occupancy is None else SPEC_VOXEL_VISIBILITY
    k = strata_per_side(vpl_samples)
    near = near_strata(vpl_samples)
    uniforms = {"strata_per_side": k, "seed": seed, "sample_index": sample,
                "rsm_view_projection": view_projection, "near_strata": near}
    samplers = {"gbuf_position": gbuf["position"], "gbuf_normal": gbuf["normal"],
                "rsm_position": rsm["position"], "rsm_normal": rsm["normal"], "rsm_flux": rsm["flux"]}
    if occupancy is not None:
        uniforms.update(grid_origin=grid.origin_m, cell_size=grid.cell_size_m, grid_dims=grid.dims,
                        offset_cells=offset_cells)
        samplers["occupancy"] = occupancy
    # Worst-case loop iterations per VPL: 1, or the march's half-cell steps across the grid diagonal.
    per_vpl = 1 if grid is None else int(np.ceil(2.0 * np.linalg.norm(grid.dims))) + 1
    # The first dispatch also makes the three squares' near draws.
    rows = max(1, (MAX_LOOP_ITERATIONS - 3 * near * near * per_vpl) // (k * per_vpl))
    for begin in range(0, k, rows):
        backend.dispatch(backend.program(spec), group_count(indirect.size, spec.local_size),
                         uniforms={**uniforms, "row_begin": begin, "row_end": min(begin + rows, k)},
                         samplers=samplers, images={"indirect": indirect})
