"""VCT radiance injection: every RSM texel's reflected flux into the six directional flux volumes.

Inputs: one RSM face (position; normal; flux, W), the VCT Grid, an Atlas. Output (accumulated over
faces and lights, cleared by the caller per update): six RGBA32F 2D textures of atlas.size, one per
direction ("px" .. "nz"), attached to `target` in DIRECTIONS order (the atlas layout below); rgb = the
sum over the cell's VPLs of phi * max(0, n.t) for the six axis directions t of travel.
vct_pyramid.level0 turns them into premultiplied radiance.

Portable scatter (ARCHITECTURE.md section 3): additive point splats, no atomics. Unlike LPV's one
draw per z-layer, the z-layers are tiles of one 2D atlas, so a face costs one draw of its texels.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from ..backends.base import Backend, Sampler, ShaderSpec, Var
from ..grid import Grid

DIRECTIONS = ("px", "nx", "py", "ny", "pz", "nz")  # travel along +x, -x, +y, -y, +z, -z

SPEC = ShaderSpec(
    name="vct_inject",
    vertex="vct/inject.vert.glsl",
    fragment="vct/inject.frag.glsl",
    samplers=(Sampler("rsm_position", "2D"), Sampler("rsm_normal", "2D"), Sampler("rsm_flux", "2D")),
    uniforms=(Var("grid_origin", "vec3"), Var("cell_size", "float"), Var("dims", "ivec3"), Var("tiles_x", "int"),
              Var("atlas_size", "ivec2")),
    attributes=(Var("texel", "vec2"),),
    varyings=(Var("v_pos", "vec3"), Var("v_neg", "vec3"), Var("v_pos_y", "vec3"), Var("v_neg_y", "vec3"),
              Var("v_pos_z", "vec3"), Var("v_neg_z", "vec3")),
    outputs=tuple(Var(f"out_{d}", "vec4") for d in DIRECTIONS),
)


@dataclass(frozen=True)
class Atlas:
    """Layer z of a grid as tile (z % tiles_x, z // tiles_x) of a 2D texture, one texel per cell: near
    square, so 128^3 fits in 1536 x 1408 texels (a strip of layers would need 16,384 rows)."""

    tiles_x: int
    size: tuple[int, int]

    @classmethod
    def for_grid(cls, grid: Grid) -> Atlas:
        nx, ny, nz = grid.dims
        tiles_x = math.ceil(math.sqrt(nz))
        return cls(tiles_x, (tiles_x * nx, math.ceil(nz / tiles_x) * ny))


def run(backend: Backend, target, points, rsm: dict, grid: Grid, atlas: Atlas) -> None:
    """Add one RSM face's VPLs into the flux atlas behind `target` (the six flux textures)."""
    backend.draw(backend.program(SPEC), target, points,
                 uniforms={"grid_origin": grid.origin_m, "cell_size": grid.cell_size_m, "dims": grid.dims,
                           "tiles_x": atlas.tiles_x, "atlas_size": atlas.size},
                 samplers={"rsm_position": rsm["position"], "rsm_normal": rsm["normal"], "rsm_flux": rsm["flux"]},
                 blend="add")
