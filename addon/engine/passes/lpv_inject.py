"""LPV injection pass: every RSM texel is a VPL added to the SH volumes (Kaplanyan 2009; seeds 002).

Inputs: one RSM face (position; normal, w = surfel area; flux, W), the LPV Grid and its Atlas. Outputs:
`run` adds into three RGBA32F 2D atlas textures `sh_r/g/b` (accumulated over faces, cleared by the
caller per update); `unpack` copies them, once per update, into the snapshot volumes `sh_r/g/b`,
RGBA32F 3D textures of grid.dims holding, per colour channel, the L1 SH (order 1, y, z, x) of the
radiant intensity in W/sr that leaves the cell, by direction of travel. A VPL of flux phi and normal n
adds phi / pi * (0.886227, 1.023327 n) (its Lambertian intensity phi / pi * max(0, n.w) projected) to
the cell containing pos + 0.6 cell * n (not half a cell: inject.vert.glsl says why); the cell's flux
is the integral of the intensity, 2 sqrt(pi) * c0 (docs/LPV.md derives the units).

Portable scatter (ARCHITECTURE.md section 3): additive point splats, no atomics. The z-layers are tiles
of one 2D atlas (passes/atlas.py: layer z is tile (z % tiles_x, z // tiles_x), one texel per cell), so
a face costs one draw of its texels; one per z-layer (the earlier form) cost texels x layers vertex
invocations, and made injection the dearest LPV pass on a GPU (docs/LPV.md, "Speed").

Emitter classes (LpvConfig.emitter_classes): the atlas holds the grid CLASSES times over, and each VPL
goes into the block of its normal's class (`emitter_class`); `unpack` copies one block (docs/LPV.md,
"Emitter classes").
"""

from __future__ import annotations

import dataclasses

import numpy as np

from ..backends.base import Backend, Image, Sampler, ShaderSpec, Var, group_count
from ..grid import Grid
from .atlas import Atlas, splat, splat_spec
from .declare import LPV_ATLAS, LPV_SNAPSHOT, RSM, PassDecl

# +x -x +y -y +z -z: a normal's dominant axis and its sign.
CLASSES = 6

SPEC = splat_spec("lpv_inject", "lpv/inject.vert.glsl", "lpv/inject.frag.glsl",
                  varyings=(Var("v_r", "vec4"), Var("v_g", "vec4"), Var("v_b", "vec4")),
                  outputs=(Var("out_r", "vec4"), Var("out_g", "vec4"), Var("out_b", "vec4")))
SPEC_CLASSES = dataclasses.replace(SPEC, name="lpv_inject_classes", defines=(("EMITTER_CLASSES", "1"),))


DECL = PassDecl("lpv_inject", "solve", RSM, (LPV_ATLAS, LPV_SNAPSHOT),
                "each face's VPLs splatted into the atlas; once per update unpacked into the snapshot")


def spec(classes: bool) -> ShaderSpec:
    """The injection program (its point mesh, atlas.texel_points, is made for it)."""
    return SPEC_CLASSES if classes else SPEC

UNPACK = ShaderSpec(
    name="lpv_unpack",
    compute="lpv/unpack.comp.glsl",
    local_size=(4, 4, 4),
    samplers=tuple(Sampler(f"atlas_{c}", "2D") for c in "rgb"),
    images=tuple(Image(f"sh_{c}", "3D", "RGBA32F", "write") for c in "rgb"),
    uniforms=(Var("dims", "ivec3"), Var("tiles_x", "int"), Var("first_layer", "int")),
)


def emitter_class(normals: np.ndarray) -> np.ndarray:
    """Class 0..5 (+x -x +y -y +z -z) of each normal (..., 3): lpv/emitter_class.glsl's twin."""
    axis = np.argmax(np.abs(normals), axis=-1)
    negative = np.take_along_axis(normals, axis[..., None], axis=-1)[..., 0] < 0
    return 2 * axis + negative


def atlas_target(backend: Backend, grid: Grid, classes: bool = False) -> tuple[Atlas, dict, object]:
    """(Atlas, its three textures keyed sh_r/g/b, the framebuffer with them attached), made once per grid;
    with `classes` the atlas holds one block of the grid per emitter class."""
    atlas = Atlas.for_grid(grid, CLASSES if classes else 1)
    textures = {f"sh_{c}": backend.texture(atlas.size) for c in "rgb"}
    return atlas, textures, backend.target([textures["sh_r"], textures["sh_g"], textures["sh_b"]])


def run(backend: Backend, target, points, rsm: dict, grid: Grid, atlas: Atlas, classes: bool = False) -> None:
    """Add one RSM face's VPLs to the atlas behind `target` (cleared by the caller per update); with
    `classes` each into its emitter class's block (`points` made for spec(classes))."""
    splat(backend, spec(classes), target, points, rsm, grid, atlas)


def unpack(backend: Backend, atlas_textures: dict, volumes: dict, grid: Grid, atlas: Atlas,
           emitter: int = 0) -> None:
    """atlas (keys sh_r/g/b, 2D) -> volumes (keys sh_r/g/b, 3D), every cell written: the atlas's block
    of emitter class `emitter` (0 when it holds one block)."""
    backend.dispatch(backend.program(UNPACK), group_count(grid.dims, UNPACK.local_size),
                     uniforms={"dims": grid.dims, "tiles_x": atlas.tiles_x, "first_layer": emitter * grid.dims[2]},
                     samplers={f"atlas_{c}": atlas_textures[f"sh_{c}"] for c in "rgb"}, images=volumes)
