"""RSM indirect gather pass (Dachsbacher & Stamminger 2005, eq. 1 with a disk term), no visibility.

Inputs: G-buffer position and normal; one RSM face's position, normal (w = surfel area, m^2) and flux
(W). Uniforms: strata_per_side (VPLs per pixel = strata_per_side^2), the face's view-projection and
near_strata (near_strata^2 draws near the receiver's own texel in each of three squares, besides the
strata), seed, sample_index; with voxel visibility also the voxelizer's occupancy (`vox_albedo`,
a = occupancy) and its grid. Output: `indirect` (RGBA32F, camera resolution), accumulated over faces
and lights, in Cycles' Diffuse Indirect unit (indirect irradiance / pi). One bounce. See
gpu_shaders/rsm/gather.comp.glsl for the estimator.

Before the gather, three small passes weigh the face's blocks by the light they send to
RECEIVERS_PER_SIDE^2 receivers spread over the G-buffer (`block_pdf`, rsm/importance*.comp.glsl): where
the view's light comes from a small part of the map, the strata draw each block with that probability,
half of it uniform; elsewhere one texel per block.
"""

from __future__ import annotations

import math

import numpy as np

from ..backends.base import Backend, Image, Sampler, ShaderSpec, Var, group_count
from ..grid import Grid
from . import surface_support
from .declare import GBUF_NORMAL, GBUF_POSITION, INDIRECT, RSM, VOX_ALBEDO, PassDecl

_SAMPLERS = (Sampler("gbuf_position", "2D"), Sampler("gbuf_normal", "2D"), Sampler("rsm_position", "2D"),
             Sampler("rsm_normal", "2D"), Sampler("rsm_flux", "2D"))
_GATHER_SAMPLERS = (*_SAMPLERS, Sampler("block_pdf", "2D"), Sampler("support", "2D"))
_UNIFORMS = (Var("strata_per_side", "int"), Var("seed", "int"), Var("sample_index", "int"), Var("row_begin", "int"),
             Var("row_end", "int"), Var("rsm_view_projection", "mat4"), Var("near_strata", "int"),
             Var("draw_set", "int"), Var("draw_sets", "int"), Var("image_sets", "int"),
             Var("support_threshold", "float"))
# Receivers per side of the grid the blocks' view importance is estimated on (256 receivers).
RECEIVERS_PER_SIDE = 16
# llvmpipe ends a shader invocation's loops after 65,535 iterations in total (FACTS.md); keep each
# dispatch's worst case below that. A GPU has no such cap; the split costs it a few dispatches.
MAX_LOOP_ITERATIONS = 60_000

SPEC = ShaderSpec(
    name="rsm_gather",
    compute="rsm/gather.comp.glsl",
    local_size=(8, 8, 1),
    samplers=_GATHER_SAMPLERS,
    images=(Image("indirect", "2D", "RGBA32F", "read_write"),),
    uniforms=_UNIFORMS,
)

SPEC_VOXEL_VISIBILITY = ShaderSpec(
    name="rsm_gather_voxel_visibility",
    compute="rsm/gather.comp.glsl",
    local_size=(8, 8, 1),
    samplers=(*_GATHER_SAMPLERS, Sampler("occupancy", "3D")),
    images=(Image("indirect", "2D", "RGBA32F", "read_write"),),
    uniforms=(*_UNIFORMS, Var("grid_origin", "vec3"), Var("cell_size", "float"), Var("grid_dims", "ivec3"),
              Var("offset_cells", "float")),
    defines=(("VOXEL_VISIBILITY", "1"),),
)


SPEC_IMPORTANCE = ShaderSpec(
    name="rsm_importance",
    compute="rsm/importance.comp.glsl",
    local_size=(8, 8, 1),
    samplers=_SAMPLERS,
    images=(Image("block_share", "2D", "R32F", "read_write"),),
    uniforms=(Var("strata_per_side", "int"), Var("receivers_per_side", "int")),
)

SPEC_IMPORTANCE_SUM = ShaderSpec(
    name="rsm_importance_sum",
    compute="rsm/importance_sum.comp.glsl",
    local_size=(8, 8, 1),
    samplers=(Sampler("block_share", "2D"),),
    images=(Image("block_mean", "2D", "R32F", "write"),),
    uniforms=(Var("strata_per_side", "int"), Var("receivers_per_side", "int")),
)

SPEC_IMPORTANCE_PDF = ShaderSpec(
    name="rsm_importance_pdf",
    compute="rsm/importance_pdf.comp.glsl",
    local_size=(8, 8, 1),
    samplers=(Sampler("block_mean", "2D"),),
    images=(Image("block_pdf", "2D", "RGBA32F", "write"),),
    uniforms=(Var("strata_per_side", "int"),),
)

DECL = PassDecl("rsm_gather", "gather", (GBUF_POSITION, GBUF_NORMAL, surface_support.SUPPORT, *RSM, VOX_ALBEDO),
                (INDIRECT,),
                "one face's VPLs gathered at every pixel (voxel visibility: through the occupancy), added")


def strata_per_side(vpl_samples: int) -> int:
    """VPLs are drawn one per block of a k x k split of the RSM: k = floor(sqrt(samples)), at least 1."""
    return max(1, math.isqrt(vpl_samples))


def near_strata(vpl_samples: int) -> int:
    """Draws near the receiver (gather.comp.glsl, "Near draws"): near_strata^2 in each of three squares,
    about half a row of strata each (1 at 16 VPLs and fewer, 3 at 256: 27 draws beside the 256)."""
    return max(1, round(math.sqrt(strata_per_side(vpl_samples) / 2)))


def _samplers(gbuf: dict, rsm: dict) -> dict:
    """The G-buffer and RSM face textures by the shaders' sampler names (_SAMPLERS)."""
    return {"gbuf_position": gbuf["position"], "gbuf_normal": gbuf["normal"],
            "rsm_position": rsm["position"], "rsm_normal": rsm["normal"], "rsm_flux": rsm["flux"]}


def importance_textures(backend: Backend, vpl_samples: int) -> dict:
    """Scratch of block_pdf for faces of up to `vpl_samples` VPLs (k^2 blocks): `block_share` (blocks x
    receivers) and `block_mean` (k x k), R32F; a face of fewer VPLs uses their corner."""
    k = strata_per_side(vpl_samples)
    return {"block_share": backend.texture((k * k, RECEIVERS_PER_SIDE**2), "R32F"),
            "block_mean": backend.texture((k, k), "R32F")}


def pdf_texture(backend: Backend, vpl_samples: int):
    """A face's block_pdf (k x k, RGBA32F) for faces of up to `vpl_samples` VPLs."""
    k = strata_per_side(vpl_samples)
    return backend.texture((k, k))


def block_pdf(backend: Backend, gbuf: dict, rsm: dict, importance: dict, vpl_samples: int, out) -> None:
    """The probability of each of the face's k x k blocks to be drawn by a strata draw, written into
    `out`.x (a pdf_texture; rsm/importance*.comp.glsl): the mean over the receivers of the share of
    their light that the block holds, half of it uniform, where that is predicted to cut the variance
    4x or more (out.y = 1), else uniform (0: the gather draws one texel per block). `importance` is
    importance_textures' scratch."""
    k = strata_per_side(vpl_samples)
    uniforms = {"strata_per_side": k, "receivers_per_side": RECEIVERS_PER_SIDE}
    backend.dispatch(backend.program(SPEC_IMPORTANCE),
                     group_count((RECEIVERS_PER_SIDE, RECEIVERS_PER_SIDE), SPEC_IMPORTANCE.local_size),
                     uniforms=uniforms, samplers=_samplers(gbuf, rsm),
                     images={"block_share": importance["block_share"]})
    blocks = group_count((k, k), SPEC_IMPORTANCE_SUM.local_size)
    backend.dispatch(backend.program(SPEC_IMPORTANCE_SUM), blocks, uniforms=uniforms,
                     samplers={"block_share": importance["block_share"]},
                     images={"block_mean": importance["block_mean"]})
    backend.dispatch(backend.program(SPEC_IMPORTANCE_PDF), blocks, uniforms={"strata_per_side": k},
                     samplers={"block_mean": importance["block_mean"]}, images={"block_pdf": out})


def run(backend: Backend, gbuf: dict, rsm: dict, indirect, vpl_samples: int, seed: int, view_projection,
        pdf, support, occupancy=None, grid: Grid | None = None, offset_cells: float = 1.5, sample: int = 0,
        draw_sets: int = 1, image_sets: int = 1) -> None:
    """Gather one RSM face (drawn through `view_projection`, the face's local-space 4 x 4) into
    `indirect`, drawing its blocks by `pdf` (block_pdf's, for this face and G-buffer); pass the
    voxelizer's `vox_albedo` and grid for visibility. `seed` is the update's; `sample` the
    gather's index among those averaged since (DirectMethod.sample_index): the draws step along a
    low-discrepancy sequence with it. `support` (surface_support's image): pixels below its THRESHOLD
    make `draw_sets` times as many sets of draws (RsmConfig.support_draws) as the `image_sets` every pixel
    makes (surface_support.image_samples), each set in dispatches of its own (the loop cap below holds
    per set) that the pixels with fewer sets leave at once."""
    spec = SPEC if occupancy is None else SPEC_VOXEL_VISIBILITY
    k = strata_per_side(vpl_samples)
    near = near_strata(vpl_samples)
    uniforms = {"strata_per_side": k, "seed": seed, "sample_index": sample,
                "rsm_view_projection": view_projection, "near_strata": near, "draw_sets": draw_sets,
                "image_sets": image_sets,
                "support_threshold": surface_support.THRESHOLD}
    samplers = {**_samplers(gbuf, rsm), "block_pdf": pdf, "support": support}
    if occupancy is not None:
        uniforms.update(grid_origin=grid.origin_m, cell_size=grid.cell_size_m, grid_dims=grid.dims,
                        offset_cells=offset_cells)
        samplers["occupancy"] = occupancy
    # Worst-case loop iterations per VPL: 1, or the march's half-cell steps across the grid diagonal.
    per_vpl = 1 if grid is None else int(np.ceil(2.0 * np.linalg.norm(grid.dims))) + 1
    # The first dispatch also makes the three squares' near draws; each walks the blocks' running sum.
    rows = max(1, (MAX_LOOP_ITERATIONS - 3 * near * near * per_vpl - k * k) // (k * per_vpl))
    for draw_set in range(draw_sets * image_sets):
        for begin in range(0, k, rows):
            backend.dispatch(backend.program(spec), group_count(indirect.size, spec.local_size),
                             uniforms={**uniforms, "row_begin": begin, "row_end": min(begin + rows, k),
                                       "draw_set": draw_set},
                             samplers=samplers, images={"indirect": indirect})
