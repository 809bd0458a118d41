"""VCT radiance injection: every RSM texel's reflected flux into the six directional flux volumes.

Inputs: one RSM face (position; normal, w = surfel area m^2; flux, W), the VCT Grid, an Atlas, the
offset along the normal (cells). Output (accumulated over faces and lights, cleared by the caller per
update): six RGBA32F 2D textures of atlas.size, one per direction ("px" .. "nz"), attached to `target`
in DIRECTIONS order (the atlas layout below); per cell and axis direction t of travel, rgb = the sum
over its VPLs of phi * max(0, n.t) and a = of their lit area A * max(0, n.t) / h^2 (cross-section
fractions). vct_pyramid.level0 turns them into premultiplied radiance and the lit surface's opacity.

Each VPL goes into the cell `inject_offset_cells` along its normal from its surfel (0.4 by default):
the voxelizer is conservative, so a tilted surface's opacity reaches cells in front of the one its
surfel lies in, which were opaque and unlit and hid its light (Sibenik read 0.53 of Cycles, 0.67 with
the offset). 0.5 put the bounds' walls, which Grid.fit centres in their cells, exactly on a cell border
(fp32 rounding then picked the cell: 2 % between scales); 0.6 and more jump light past an occluder as
close as emissive's panel under the ceiling (bias 0.81 -> 2.3). docs/VCT.md has the table.

Portable scatter (ARCHITECTURE.md section 3): additive point splats into the layers-as-tiles atlas
(passes/atlas.py), one draw per face.
"""

from __future__ import annotations

from ..backends.base import Backend, Var
from ..grid import Grid
from .atlas import Atlas, splat, splat_spec

DIRECTIONS = ("px", "nx", "py", "ny", "pz", "nz")  # travel along +x, -x, +y, -y, +z, -z

SPEC = splat_spec("vct_inject", "vct/inject.vert.glsl", "vct/inject.frag.glsl",
                  varyings=tuple(Var(f"v_{d}", "vec4") for d in DIRECTIONS),
                  outputs=tuple(Var(f"out_{d}", "vec4") for d in DIRECTIONS),
                  uniforms=(Var("inject_offset_cells", "float"),))


def run(backend: Backend, target, points, rsm: dict, grid: Grid, atlas: Atlas, inject_offset_cells: float) -> None:
    """Add one RSM face's VPLs into the flux atlas behind `target` (the six flux textures)."""
    splat(backend, SPEC, target, points, rsm, grid, atlas, {"inject_offset_cells": inject_offset_cells})
