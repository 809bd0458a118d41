"""LPV lookup pass: the accumulated SH at every G-buffer pixel -> `indirect`.

Inputs: G-buffer position and normal; `acc_r/g/b` (RGBA32F 3D, accumulated L1 SH of radiant intensity,
W/sr per cell, by direction of travel), the Grid. Output: `indirect` (RGBA32F, camera size, written;
added to with `accumulate`): E / pi with E = max(0, c(p) . cosine_lobe(-n)) / h^2, c(p) trilinear at
p = pos + lookup_offset_cells * h * n. Units: Cycles' Diffuse Indirect (docs/LPV.md). With several
bounces the method runs it once per bounce's volume, the later ones added (`accumulate`): each bounce's
irradiance is clamped at 0 on its own. With `vox_normal` (the improved variant's geometry volume) the 8
trilinear corners are weighted by their transmittance along n, 1 - min(1, w |n_cell . n|), and
renormalised: the cells a surface blocks hold light its own geometry attenuated, not the light arriving
at it (docs/LPV.md, "Geometry-aware lookup"). With `cascade` (a finer LPV cascade, lpv_cascade.Cascade)
`indirect` holds the parent cascades' answer and is blended towards this grid's across the transition
band inside its interior faces (lpv_cascade.blend_weight); run coarsest first. A later bounce over
cascades is looked up that way into an image of its own, then `add_image` adds it to `indirect`.

Emitter classes (one cascade; docs/LPV.md, "Emitter classes"): `own` runs once per class with that
class's light alone, writing the signed reading at the pixels of that class into `own_light` (RGBA32F,
camera size); `run` with own_light then subtracts it from the total's reading before the clamp.
"""

from __future__ import annotations

from ..backends.base import Backend, Image, Sampler, ShaderSpec, Var, group_count
from ..grid import Grid
from . import lpv_cascade
from .declare import GBUF_NORMAL, GBUF_POSITION, INDIRECT, LPV_ACCUMULATED, VOX_NORMAL, PassDecl
from .lpv_cascade import Cascade

DECL = PassDecl("lpv_lookup", "gather", (GBUF_POSITION, GBUF_NORMAL, LPV_ACCUMULATED, VOX_NORMAL), (INDIRECT,),
                "the accumulated SH read at every pixel")


def _spec(accumulate: bool, geometry_volume: bool, cascade: bool, own: str = "") -> ShaderSpec:
    """own: "" (plain), "pass" (one emitter class's reading -> own_light) or "subtract" (the total's
    reading minus own_light)."""
    defines = (("ACCUMULATE", "1"),) if accumulate else ()
    extra = ()
    uniforms = ()
    image = Image("indirect", "2D", "RGBA32F", "read_write" if accumulate or cascade else "write")
    if geometry_volume:
        defines += (("GEOMETRY_VOLUME", "1"),)
        extra = (Sampler("vox_normal", "3D"),)
    if cascade:
        defines += (("CASCADE", "1"),)
        uniforms = (Var("interior_lo", "ivec3"), Var("interior_hi", "ivec3"), Var("band_start", "float"),
                    Var("band_cells", "float"))
    if own == "pass":
        defines += (("EMITTER_PASS", "1"),)
        uniforms = (Var("emitter", "int"),)
        image = Image("own_light", "2D", "RGBA32F", "write")
    elif own == "subtract":
        defines += (("OWN_LIGHT", "1"),)
        extra += (Sampler("own_light", "2D"),)
    return ShaderSpec(
        name=("lpv_lookup_add" if accumulate else "lpv_lookup") + ("_gv" if geometry_volume else "")
        + ("_cascade" if cascade else "") + (f"_own_{own}" if own else ""),
        compute="lpv/lookup.comp.glsl",
        local_size=(8, 8, 1),
        samplers=(Sampler("gbuf_position", "2D"), Sampler("gbuf_normal", "2D"), Sampler("acc_r", "3D"),
                  Sampler("acc_g", "3D"), Sampler("acc_b", "3D")) + extra,
        images=(image,),
        uniforms=(Var("grid_origin", "vec3"), Var("cell_size", "float"), Var("dims", "ivec3"),
                  Var("lookup_offset_cells", "float")) + uniforms,
        defines=defines,
    )


SPECS = {(acc, gv, cas): _spec(acc, gv, cas) for acc in (False, True) for gv in (False, True)
         for cas in (False, True) if not (acc and cas)}
OWN_SPECS = {(own, gv): _spec(False, gv, False, own) for own in ("pass", "subtract") for gv in (False, True)}

# A later bounce over cascades: `accumulate` cannot blend (the parent's share of this bounce would stay
# in full under the finer cascade's), so the bounce is looked up into its own image and added.
ADD_IMAGE = ShaderSpec(
    name="lpv_add_image",
    compute="lpv/add_image.comp.glsl",
    local_size=(8, 8, 1),
    samplers=(Sampler("bounce_image", "2D"),),
    images=(Image("indirect", "2D", "RGBA32F", "read_write"),),
)


def run(backend: Backend, gbuf: dict, acc: dict, indirect, grid: Grid, offset_cells: float = 0.5,
        accumulate: bool = False, vox_normal=None, cascade: Cascade | None = None, own_light=None) -> None:
    """Write `indirect` from `acc`, or with `accumulate` add to it (one later bounce's volume), or with
    `cascade` (whose grid is `grid`) blend it in across its band; with `vox_normal` (the geometry volume)
    the trilinear corners are weighted by their transmittance; with `own_light` (written by `own` for
    every class; not with accumulate or cascade) each pixel's own class's reading is subtracted."""
    if own_light is not None:
        spec = OWN_SPECS[("subtract", vox_normal is not None)]
    else:
        spec = SPECS[(accumulate, vox_normal is not None, cascade is not None)]
    samplers = {"gbuf_position": gbuf["position"], "gbuf_normal": gbuf["normal"], **acc}
    if vox_normal is not None:
        samplers["vox_normal"] = vox_normal
    if own_light is not None:
        samplers["own_light"] = own_light
    uniforms = {"grid_origin": grid.origin_m, "cell_size": grid.cell_size_m, "dims": grid.dims,
                "lookup_offset_cells": offset_cells}
    if cascade is not None:
        uniforms.update(interior_lo=cascade.interior_lo, interior_hi=cascade.interior_hi,
                        band_start=lpv_cascade.BAND_START_CELLS, band_cells=lpv_cascade.BAND_CELLS)
    backend.dispatch(backend.program(spec), group_count(indirect.size, spec.local_size), uniforms=uniforms,
                     samplers=samplers, images={"indirect": indirect})


def own(backend: Backend, gbuf: dict, acc: dict, own_light, grid: Grid, emitter: int, offset_cells: float = 0.5,
        vox_normal=None) -> None:
    """own_light at the pixels whose normal is of class `emitter` := the signed reading of `acc` (that
    class's light alone), as `run` reads it before the clamp; other pixels are left as they are."""
    spec = OWN_SPECS[("pass", vox_normal is not None)]
    samplers = {"gbuf_position": gbuf["position"], "gbuf_normal": gbuf["normal"], **acc}
    if vox_normal is not None:
        samplers["vox_normal"] = vox_normal
    backend.dispatch(backend.program(spec), group_count(own_light.size, spec.local_size),
                     uniforms={"grid_origin": grid.origin_m, "cell_size": grid.cell_size_m, "dims": grid.dims,
                               "lookup_offset_cells": offset_cells, "emitter": emitter},
                     samplers=samplers, images={"own_light": own_light})


def add_image(backend: Backend, bounce_image, indirect) -> None:
    """indirect += bounce_image (one later bounce, looked up over the cascades on its own)."""
    backend.dispatch(backend.program(ADD_IMAGE), group_count(indirect.size, ADD_IMAGE.local_size),
                     samplers={"bounce_image": bounce_image}, images={"indirect": indirect})
