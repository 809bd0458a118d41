"""The layers-as-tiles atlas shared by the LPV and VCT injections (gpu_shaders/common/atlas.glsl).

A grid's z-layer z is tile (z % tiles_x, z // tiles_x) of one 2D texture, one texel per cell, so an
RSM face's VPLs are splatted into every layer with one point draw (additive blending; portable, no
atomics) instead of one draw per layer. Compute passes read cells back with atlas_texel().
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..backends.base import Backend, Sampler, ShaderSpec, Var
from ..grid import Grid


@dataclass(frozen=True)
class Atlas:
    """Near square, so 128^3 fits in 1536 x 1408 texels (a strip of layers would need 16,384 rows)."""

    tiles_x: int
    size: tuple[int, int]

    @classmethod
    def for_grid(cls, grid: Grid, blocks: int = 1) -> Atlas:
        """The grid's z-layers `blocks` times over (block b's layer z is layer b * nz + z)."""
        nx, ny, nz = grid.dims
        nz *= blocks
        tiles_x = math.ceil(math.sqrt(nz))
        return cls(tiles_x, (tiles_x * nx, math.ceil(nz / tiles_x) * ny))


def splat_spec(name: str, vertex: str, fragment: str, varyings: tuple, outputs: tuple,
               samplers: tuple = ()) -> ShaderSpec:
    """A splatting program's declaration: the RSM samplers, grid and atlas uniforms and the texel
    attribute that `splat` and `texel_points` provide, plus the program's own varyings and outputs."""
    return ShaderSpec(
        name=name,
        vertex=vertex,
        fragment=fragment,
        samplers=(Sampler("rsm_position", "2D"), Sampler("rsm_normal", "2D"), Sampler("rsm_flux", "2D"), *samplers),
        uniforms=(Var("grid_origin", "vec3"), Var("cell_size", "float"), Var("dims", "ivec3"),
                  Var("tiles_x", "int"), Var("atlas_size", "ivec2")),
        attributes=(Var("texel", "vec2"),),
        varyings=varyings,
        outputs=outputs,
    )


def texel_points(backend: Backend, resolution: int | tuple[int, int], spec: ShaderSpec, copies: int = 1):
    """The point mesh: `copies` consecutive vertices per RSM texel (its integer coordinates, attribute
    `texel`; a program tells the copies apart by gl_VertexID % copies), made once per RSM size (square,
    or (width, height)) for the splatting program `spec`."""
    width, height = (resolution, resolution) if isinstance(resolution, int) else resolution
    j, i = np.mgrid[0:height, 0:width]
    texels = np.stack([i.ravel(), j.ravel()], axis=1).astype(np.float32)
    texels = np.repeat(texels, copies, axis=0)
    return backend.mesh(backend.program(spec), {"texel": texels}, "points")


def splat(backend: Backend, spec: ShaderSpec, target, points, rsm: dict, grid: Grid, atlas: Atlas,
          samplers: dict | None = None) -> None:
    """Draw one RSM face's VPLs with `spec` into the atlas textures behind `target`, added."""
    backend.draw(backend.program(spec), target, points,
                 uniforms={"grid_origin": grid.origin_m, "cell_size": grid.cell_size_m, "dims": grid.dims,
                           "tiles_x": atlas.tiles_x, "atlas_size": atlas.size},
                 samplers={"rsm_position": rsm["position"], "rsm_normal": rsm["normal"], "rsm_flux": rsm["flux"],
                           **(samplers or {})},
                 blend="add")
