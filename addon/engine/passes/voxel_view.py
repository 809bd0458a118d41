"""Debug view of a voxel grid on the camera's surfaces (the viewport's "Voxels" mode).

Inputs: G-buffer position; the voxelizer's `vox_albedo` (a = occupancy) and its Grid. Output: `view`
(RGBA32F, camera resolution): the voxel's albedo with a checkerboard by cell parity, magenta where a
visible surface point lies in an empty voxel (a hole). Not light: shown without the albedo factor.
"""

from __future__ import annotations

from ..backends.base import Backend, Image, Sampler, ShaderSpec, Var, group_count
from ..grid import Grid
from .declare import GBUF_POSITION, VOX_ALBEDO, VOXEL_VIEW, PassDecl

SPEC = ShaderSpec(
    name="voxel_view",
    compute="voxelize/view.comp.glsl",
    local_size=(8, 8, 1),
    samplers=(Sampler("gbuf_position", "2D"), Sampler("vox_albedo", "3D")),
    images=(Image("view", "2D", "RGBA32F", "write"),),
    uniforms=(Var("grid_origin", "vec3"), Var("cell_size", "float"), Var("grid_dims", "ivec3")),
)


DECL = PassDecl("voxel_view", "gather", (GBUF_POSITION, VOX_ALBEDO), (VOXEL_VIEW,), "the voxel grid on the surfaces")


def run(backend: Backend, gbuf_position, vox_albedo, grid: Grid, view) -> None:
    backend.dispatch(backend.program(SPEC), group_count(view.size, SPEC.local_size),
                     uniforms={"grid_origin": grid.origin_m, "cell_size": grid.cell_size_m, "grid_dims": grid.dims},
                     samplers={"gbuf_position": gbuf_position, "vox_albedo": vox_albedo}, images={"view": view})
