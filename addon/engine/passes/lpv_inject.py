"""LPV injection pass: every RSM texel is a VPL added to the SH volumes (Kaplanyan 2009; seeds 002).

Inputs: one RSM face (position; normal, w = surfel area; flux, W), the LPV Grid and its Atlas. Outputs:
`run` adds into three RGBA32F 2D atlas textures `sh_r/g/b` (accumulated over faces, cleared by the
caller per update); `unpack` copies them, once per update, into the snapshot volumes `sh_r/g/b`,
RGBA32F 3D textures of grid.dims holding, per colour channel, the L1 SH (order 1, y, z, x) of the
radiant intensity in W/sr that leaves the cell, by direction of travel. A VPL of flux phi and normal n
adds phi / pi * (0.886227, 1.023327 n) (its Lambertian intensity phi / pi * max(0, n.w) projected) to
the cell containing pos + 0.5 cell * n; the cell's flux is the integral of the intensity,
2 sqrt(pi) * c0 (docs/LPV.md derives the units).

Portable scatter (ARCHITECTURE.md section 3): additive point splats, no atomics. The z-layers are tiles
of one 2D atlas (passes/atlas.py: layer z is tile (z % tiles_x, z // tiles_x), one texel per cell), so
a face costs one draw of its texels; one per z-layer (the earlier form) cost texels x layers vertex
invocations, and made injection the dearest LPV pass on a GPU (docs/LPV.md, "Speed").
"""

from __future__ import annotations

from ..backends.base import Backend, Image, Sampler, ShaderSpec, Var, group_count
from ..grid import Grid
from .atlas import Atlas, splat, splat_spec

SPEC = splat_spec("lpv_inject", "lpv/inject.vert.glsl", "lpv/inject.frag.glsl",
                  varyings=(Var("v_r", "vec4"), Var("v_g", "vec4"), Var("v_b", "vec4")),
                  outputs=(Var("out_r", "vec4"), Var("out_g", "vec4"), Var("out_b", "vec4")))

UNPACK = ShaderSpec(
    name="lpv_unpack",
    compute="lpv/unpack.comp.glsl",
    local_size=(4, 4, 4),
    samplers=tuple(Sampler(f"atlas_{c}", "2D") for c in "rgb"),
    images=tuple(Image(f"sh_{c}", "3D", "RGBA32F", "write") for c in "rgb"),
    uniforms=(Var("dims", "ivec3"), Var("tiles_x", "int")),
)


def atlas_target(backend: Backend, grid: Grid) -> tuple[Atlas, dict, object]:
    """(Atlas, its three textures keyed sh_r/g/b, the framebuffer with them attached), made once per grid."""
    atlas = Atlas.for_grid(grid)
    textures = {f"sh_{c}": backend.texture(atlas.size) for c in "rgb"}
    return atlas, textures, backend.target([textures["sh_r"], textures["sh_g"], textures["sh_b"]])


def run(backend: Backend, target, points, rsm: dict, grid: Grid, atlas: Atlas) -> None:
    """Add one RSM face's VPLs to the atlas behind `target` (cleared by the caller per update)."""
    splat(backend, SPEC, target, points, rsm, grid, atlas)


def unpack(backend: Backend, atlas_textures: dict, volumes: dict, grid: Grid, atlas: Atlas) -> None:
    """atlas (keys sh_r/g/b, 2D) -> volumes (keys sh_r/g/b, 3D), every cell written."""
    backend.dispatch(backend.program(UNPACK), group_count(grid.dims, UNPACK.local_size),
                     uniforms={"dims": grid.dims, "tiles_x": atlas.tiles_x},
                     samplers={f"atlas_{c}": atlas_textures[f"sh_{c}"] for c in "rgb"}, images=volumes)
