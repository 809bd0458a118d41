"""Diffusion injection and emitters: the cells' direct light as Lambertian L1 SH lobes about their planes.

`run` (per RSM face): additive point splats of the face's VPLs (flux phi, W) into two RGBA32F atlases
of the grid's layers (passes/atlas.py, the splat the LPV and VCT injections use): `flux_plus` and
`flux_minus`, the flux each side of a cell's plane receives from its VPLs, the VPL in the cell holding
its surface (or half a cell behind it when that one is empty), on the side its normal faces.
`emit` (once per bounce): the flux on each side -> the snapshot `sh_r/g/b` (RGBA32F 3D, L1 SH of
radiant intensity W/sr by direction of travel): flux / pi x the clamped-cosine lobe about that side's
normal, times the voxels' albedo for later bounces (whose flux is what the surfaces absorbed); an empty
cell emits isotropically. With an `emitter_class` only that class's sides emit (the propagation of one
emitter class, docs/DIFFUSION.md "Emitter classes"). Twin: diffusion_reference.inject / emit.
"""

from __future__ import annotations

import functools

from ..backends.base import Backend, Image, Sampler, ShaderSpec, Var, group_count
from ..grid import Grid
from .atlas import Atlas, splat, splat_spec
from .declare import RSM, VOX_ALBEDO, PassDecl, Port
from .diffusion_cells import CELL_BLOCK, CELL_NORMAL
from .diffusion_cone_defines import cone_defines

INJECTED = Port("diffusion", "injected", "RGBA32F", "atlas",
                "VPL flux (W) on each side of a cell's plane, by layer tile")
# Emitter classes (diffusion/cell.glsl): a side's class is its normal's dominant signed axis, 0..5.
EVERY_CLASS = -1
EMITTER_CLASSES = tuple(range(6))

SNAPSHOT = Port("diffusion", "snapshots", "RGBA32F", "grid", "L1 SH of radiant intensity (W/sr) in each cell")

SPEC = splat_spec("diffusion_inject", "diffusion/inject.vert.glsl", "diffusion/inject.frag.glsl",
                  varyings=(Var("v_plus", "vec4"), Var("v_minus", "vec4")),
                  outputs=(Var("out_plus", "vec4"), Var("out_minus", "vec4")),
                  samplers=(Sampler("cell_normal", "3D"),))

DECL = PassDecl("diffusion_inject", "solve", (*RSM, CELL_NORMAL), (INJECTED,),
                "each face's VPLs splatted by side of their cell's plane")


@functools.cache
def emit_spec(atlas: bool, cone: int | None = None) -> ShaderSpec:
    """From the injection atlases (the first bounce: VPL flux is reflected light already), or from a
    bounce's absorbed flux times the voxels' albedo (the next bounce); with a `cone`, that cone field's
    part of the emitters (cone_fields.py)."""
    dim = "2D" if atlas else "3D"
    samplers = (Sampler("flux_plus", dim), Sampler("flux_minus", dim), Sampler("cell_normal", "3D"),
                Sampler("cell_block", "3D"))
    uniforms = (Var("dims", "ivec3"), Var("emitting_class", "int"))
    if atlas:
        uniforms += (Var("tiles_x", "int"),)
    else:
        samplers += (Sampler("vox_albedo", "3D"),)
    name = "diffusion_emit" + ("_atlas" if atlas else "_albedo") + ("" if cone is None else f"_cone_field_{cone}")
    return ShaderSpec(name=name, compute="diffusion/emit.comp.glsl",
                      local_size=(4, 4, 4), samplers=samplers,
                      images=tuple(Image(f"sh_{c}", "3D", "RGBA32F", "write") for c in "rgb"), uniforms=uniforms,
                      defines=((("ATLAS", "1"),) if atlas else (("ALBEDO", "1"),))
                      + (cone_defines(cone) if cone is not None else ()))


EMIT_DECL = PassDecl("diffusion_emit", "solve", (INJECTED, CELL_NORMAL, CELL_BLOCK, VOX_ALBEDO), (SNAPSHOT,),
                     "each side's flux as a Lambertian lobe about its normal (x albedo for later bounces)")


def atlas_target(backend: Backend, grid: Grid) -> tuple[Atlas, dict, object]:
    """(Atlas, its textures keyed flux_plus / flux_minus, the framebuffer with them attached)."""
    atlas = Atlas.for_grid(grid)
    textures = {k: backend.texture(atlas.size) for k in ("flux_plus", "flux_minus")}
    return atlas, textures, backend.target([textures["flux_plus"], textures["flux_minus"]])


def run(backend: Backend, target, points, rsm: dict, grid: Grid, atlas: Atlas, cell_normal) -> None:
    """Add one RSM face's VPLs to the atlases behind `target` (cleared by the caller per update)."""
    splat(backend, SPEC, target, points, rsm, grid, atlas, {"cell_normal": cell_normal})


def emit(backend: Backend, flux: dict, cells: dict, snapshot: dict, grid: Grid, atlas: Atlas | None = None,
         vox_albedo=None, emitter_class: int = EVERY_CLASS, cone: int | None = None) -> None:
    """snapshot (sh_r/g/b) := the emitters of `flux` (flux_plus / flux_minus): the injection atlases
    (`atlas` given), or volumes of absorbed flux re-emitted times `vox_albedo`; of the sides of
    `emitter_class` alone (0..5: the dominant signed axis of the side's normal, as the faces +x -x +y -y
    +z -z) unless it is EVERY_CLASS. Every cell written."""
    spec = emit_spec(atlas is not None, cone)
    samplers = {"flux_plus": flux["flux_plus"], "flux_minus": flux["flux_minus"], **cells}
    uniforms = {"dims": grid.dims, "emitting_class": emitter_class}
    if atlas is not None:
        uniforms["tiles_x"] = atlas.tiles_x
    else:
        samplers["vox_albedo"] = vox_albedo
    backend.dispatch(backend.program(spec), group_count(grid.dims, spec.local_size), uniforms=uniforms,
                     samplers=samplers, images=snapshot)


