"""VCT radiance injection: every RSM texel's reflected flux into the six directional flux volumes.

Inputs: one RSM face (position; normal; flux, W), the VCT Grid, an Atlas. Output (accumulated over
faces and lights, cleared by the caller per update): six RGBA32F 2D textures of atlas.size, one per
direction ("px" .. "nz"), attached to `target` in DIRECTIONS order (the atlas layout below); rgb = the
sum over the cell's VPLs of phi * max(0, n.t) for the six axis directions t of travel.
vct_pyramid.level0 turns them into premultiplied radiance.

Portable scatter (ARCHITECTURE.md section 3): additive point splats into the layers-as-tiles atlas
(passes/atlas.py), one draw per face.
"""

from __future__ import annotations

from ..backends.base import Backend, Var
from ..grid import Grid
from .atlas import Atlas, splat, splat_spec

DIRECTIONS = ("px", "nx", "py", "ny", "pz", "nz")  # travel along +x, -x, +y, -y, +z, -z

SPEC = splat_spec("vct_inject", "vct/inject.vert.glsl", "vct/inject.frag.glsl",
                  varyings=tuple(Var(f"v_{d}", "vec3") for d in DIRECTIONS),
                  outputs=tuple(Var(f"out_{d}", "vec4") for d in DIRECTIONS))


def run(backend: Backend, target, points, rsm: dict, grid: Grid, atlas: Atlas) -> None:
    """Add one RSM face's VPLs into the flux atlas behind `target` (the six flux textures)."""
    splat(backend, SPEC, target, points, rsm, grid, atlas)
