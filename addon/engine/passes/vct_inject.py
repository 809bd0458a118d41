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

from ..backends.base import Backend, Sampler, ShaderSpec, Var
from ..grid import Grid
from .atlas import Atlas, splat

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


def run(backend: Backend, target, points, rsm: dict, grid: Grid, atlas: Atlas) -> None:
    """Add one RSM face's VPLs into the flux atlas behind `target` (the six flux textures)."""
    splat(backend, SPEC, target, points, rsm, grid, atlas)
