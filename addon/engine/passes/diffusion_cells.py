"""Diffusion cells: what the `diffusion` transport needs of the voxels, once per voxelization.

Inputs: the voxelizer's vox_albedo (a = occupancy), vox_normal (mean normal), vox_projected (per axis
projected area, cells^2). Outputs (RGBA32F 3D, grid.dims): `cell_normal` (xyz = the surface's plane, unit;
w = each side's receiving area, cells^2) and `cell_block` (xyz = per axis the share of a face's inflow
the surface absorbs; w = 0 empty, else 1 + the mask of open faces). Twin: diffusion_reference.cells,
which says why each is what it is (docs/DIFFUSION.md, "Cells").
"""

from __future__ import annotations

from ..backends.base import Backend, Image, Sampler, ShaderSpec, Var, group_count
from ..grid import Grid
from .declare import VOX_ALBEDO, VOX_NORMAL, VOX_PROJECTED, PassDecl, Port

CELL_NORMAL = Port("diffusion", "cell_normal", "RGBA32F", "grid",
                   "xyz: the cell's surface plane (unit), w: each side's receiving area (cells^2)")
CELL_BLOCK = Port("diffusion", "cell_block", "RGBA32F", "grid",
                  "xyz: share of a face's inflow absorbed per axis; w: 0 empty, else 1 + open-face mask")

SPEC = ShaderSpec(
    name="diffusion_cells",
    compute="diffusion/cells.comp.glsl",
    local_size=(4, 4, 4),
    samplers=(Sampler("vox_albedo", "3D"), Sampler("vox_normal", "3D"), Sampler("vox_projected", "3D")),
    images=(Image("cell_normal", "3D", "RGBA32F", "write"), Image("cell_block", "3D", "RGBA32F", "write")),
    uniforms=(Var("dims", "ivec3"),),
)

DECL = PassDecl("diffusion_cells", "setup", (VOX_ALBEDO, VOX_NORMAL, VOX_PROJECTED), (CELL_NORMAL, CELL_BLOCK),
                "the voxels' planes, absorption and open faces, once per voxelization")


def textures(backend: Backend, grid: Grid) -> dict:
    return {p.name: backend.texture(grid.dims, p.format) for p in (CELL_NORMAL, CELL_BLOCK)}


def run(backend: Backend, voxels: dict, cells: dict, grid: Grid) -> None:
    """cells (textures from `textures`) from the voxels, every cell written."""
    backend.dispatch(backend.program(SPEC), group_count(grid.dims, SPEC.local_size), uniforms={"dims": grid.dims},
                     samplers={k: voxels[k] for k in ("vox_albedo", "vox_normal", "vox_projected")}, images=cells)
