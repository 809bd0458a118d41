"""Diffusion reconstruction: the light field at every G-buffer point -> `indirect`.

Inputs: G-buffer position and normal, the cells (diffusion_cells), the accumulated flux per side
(`flux_plus` / `flux_minus`, W). Output: `indirect` (RGBA32F, image size, written) = E / pi, Cycles'
Diffuse Indirect: over the 8 cells whose centres surround the point, each occupied one's irradiance on
its side facing the normal, flux / (receiving area x h^2), weighted by trilinear weight x |n . n_cell|
and renormalised; a defined fallback (the trilinear weights alone, or 0 with no occupied cell).
Twin: diffusion_reference.lookup.
"""

from __future__ import annotations

from ..backends.base import Backend, Image, Sampler, ShaderSpec, Var, group_count
from ..grid import Grid
from .declare import GBUF_NORMAL, GBUF_POSITION, INDIRECT, PassDecl
from .diffusion_cells import CELL_BLOCK, CELL_NORMAL
from .diffusion_propagate import ACCUMULATED

SPEC = ShaderSpec(
    name="diffusion_lookup",
    compute="diffusion/lookup.comp.glsl",
    local_size=(8, 8, 1),
    samplers=(Sampler("gbuf_position", "2D"), Sampler("gbuf_normal", "2D"), Sampler("cell_normal", "3D"),
              Sampler("cell_block", "3D"), Sampler("flux_plus", "3D"), Sampler("flux_minus", "3D")),
    images=(Image("indirect", "2D", "RGBA32F", "write"),),
    uniforms=(Var("grid_origin", "vec3"), Var("cell_size", "float"), Var("dims", "ivec3")),
)

DECL = PassDecl("diffusion_lookup", "gather", (GBUF_POSITION, GBUF_NORMAL, CELL_NORMAL, CELL_BLOCK, ACCUMULATED),
                (INDIRECT,), "the absorbed flux read back as irradiance at every pixel")


def run(backend: Backend, gbuf: dict, cells: dict, total: dict, indirect, grid: Grid) -> None:
    backend.dispatch(backend.program(SPEC), group_count(indirect.size, SPEC.local_size),
                     uniforms={"grid_origin": grid.origin_m, "cell_size": grid.cell_size_m, "dims": grid.dims},
                     samplers={"gbuf_position": gbuf["position"], "gbuf_normal": gbuf["normal"], **cells, **total},
                     images={"indirect": indirect})
