"""VCT radiance injection: every RSM texel's reflected flux into the six directional flux volumes,
one light at a time.

run (per RSM face): additive point splats of the face's VPLs into a light's scratch atlas: six RGBA32F
2D textures of atlas.size, one per direction ("px" .. "nz") attached to `target` in DIRECTIONS order;
per cell and axis direction t of travel, rgb = the sum over its VPLs of phi * max(0, n.t) (W) and a =
of their surfel areas A * max(0, n.t) / h^2 (RSM footprints, cross-section fractions).
add_light (once per light, after its faces): adds rgb x min(1, 4 x projected area along t / a) to the
flux atlas vct_pyramid.level0 reads: a VPL whose footprint overhangs the sliver of geometry its cell
holds no longer makes that cell hundreds of times brighter than the surface
(gpu_shaders/vct/add_light.comp.glsl). Linear in each light's power, and lights add.

Inputs: one RSM face (position; normal, w = surfel area m^2; flux, W), the VCT Grid, an Atlas; the
voxelizer's vox_projected. Portable scatter (ARCHITECTURE.md section 3): additive point splats into the
layers-as-tiles atlas (passes/atlas.py), one draw per face; the light's addition is a compute pass.
"""

from __future__ import annotations

from ..backends.base import Backend, Image, Sampler, ShaderSpec, Var, group_count
from ..grid import Grid
from .atlas import Atlas, splat, splat_spec

DIRECTIONS = ("px", "nx", "py", "ny", "pz", "nz")  # travel along +x, -x, +y, -y, +z, -z

SPEC = splat_spec("vct_inject", "vct/inject.vert.glsl", "vct/inject.frag.glsl",
                  varyings=tuple(Var(f"v_{d}", "vec4") for d in DIRECTIONS),
                  outputs=tuple(Var(f"out_{d}", "vec4") for d in DIRECTIONS))

ADD_LIGHT = ShaderSpec(
    name="vct_add_light",
    compute="vct/add_light.comp.glsl",
    local_size=(4, 4, 4),
    samplers=(*(Sampler(f"light_{d}", "2D") for d in DIRECTIONS), Sampler("vox_projected", "3D")),
    images=tuple(Image(f"flux_{d}", "2D", "RGBA32F", "read_write") for d in DIRECTIONS),
    uniforms=(Var("dims", "ivec3"), Var("tiles_x", "int")),
)


def run(backend: Backend, target, points, rsm: dict, grid: Grid, atlas: Atlas) -> None:
    """Add one RSM face's VPLs into the light's scratch atlas behind `target` (six textures)."""
    splat(backend, SPEC, target, points, rsm, grid, atlas)


def add_light(backend: Backend, light: dict, flux: dict, vox_projected, grid: Grid, atlas: Atlas) -> None:
    """flux[d] += the light's scratch light[d], capped where footprints overhang the geometry (module doc)."""
    backend.dispatch(backend.program(ADD_LIGHT), group_count(grid.dims, ADD_LIGHT.local_size),
                     uniforms={"dims": grid.dims, "tiles_x": atlas.tiles_x},
                     samplers={**{f"light_{d}": light[d] for d in DIRECTIONS}, "vox_projected": vox_projected},
                     images={f"flux_{d}": flux[d] for d in DIRECTIONS})
