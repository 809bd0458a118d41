"""Direct-light pass: shadow-mapped direct diffuse light of one light face at every G-buffer pixel.

Inputs: G-buffer position and normal, the face's RSM position, normal and flux (its w names the triangle
each texel sees) and the occluder table of those triangles (rsm.occluder_table; the shadow test), LightView
uniforms, and the emitter table (area_light.emitter_table): a light with polygons (poly_count > 0: an area light's
patch, an emissive mesh's triangles) gives the exact unshadowed irradiance of its shape, soft-shadowed
from its position as a disc of its area (emitter_radius_m); the others are points (spots masked,
area lights without a size Lambertian).
Output: `direct` (RGBA32F, camera resolution), accumulated over faces and lights, in the unit of
Cycles' Diffuse Direct pass: irradiance / pi. Point-light faces split directions by major axis, so
each pixel is shaded by exactly one face.
"""

from __future__ import annotations

import functools

from ..backends.base import Backend, Image, Sampler, ShaderSpec, Var, group_count
from . import rsm
from .declare import (
    DIRECT,
    EMITTERS,
    GBUF_NORMAL,
    GBUF_POSITION,
    LIGHT_VIEWS,
    OCCLUDERS,
    RSM_FLUX,
    RSM_NORMAL,
    RSM_POSITION,
    PassDecl,
)
from .light_views import KIND_CODE, LightView

# Crossings nearer a shadow segment's start than this many shadow-map texels do not shadow (the exact
# tests: here and the sky pass's rays). In a camera's G-buffer the depth test may keep a floor point a
# hair beyond a wall's plane where the two meet, and its segment would cross the wall at once: cornell's
# floor-wall seam read 0 over 14 pixels without this margin.
CAMERA_NEAR_TEXELS = 0.05
# A bake's texels are points of their own surface that no depth test chose: only fp32's rounding of a
# position (1e-4 texels of a 1024-texel map) needs a margin. The camera's would let a face hidden
# against another see past that one's edge: window-sky's SouthWall end face, pressed against the
# WestWall, read 0.57-1.35 along the row of texels nearest the corner (Cycles: 0; docs/BAKE.md).
SURFACE_NEAR_TEXELS = 0.001


@functools.cache  # one spec, hence one program, per kind
def _spec(polygons: bool, soft_sun: bool, area_samples: int = 0) -> ShaderSpec:
    """The pass for one kind of light: with its polygons' irradiance (POLYGONS: the emitter table and
    its rows) or a point's, with a sun's soft shadows (SOFT_SUN: the sun's angle) or a hard shadow; a
    point's and a sun's shadows tested against the triangles the map names (rsm_flux's w, the occluders
    table: docs/DIRECT.md, "The shadow test").
    One program each, because llvmpipe runs the code of a branch no invocation takes: with both kinds in
    one program a spot's shading of the probe atlas took 4.5 x as long (docs/PROBES.md).
    area_samples 0: every pixel of the G-buffer. On the probe atlas, one invocation per texel of a list
    (TEXEL_LIST, `texel_list`: probe_capture.texel_lists), so that the texels that see nothing cost no
    invocation (docs/PROBES.md, "What the light update costs"): area_samples 1, each at its centre;
    > 1 (AREA_SAMPLES, ProbesConfig.area_samples), the grazing texels at that many points along their
    footprints (probe_capture.FOOTPRINT)."""
    area = area_samples > 1
    exact = not polygons  # the exact shadow test: the triangles the map names
    listed = ("texel_list",) if area_samples >= 1 else ()
    footprint = ("footprint_origin", "footprint_step", "footprint_neighbours") if area else ()
    return ShaderSpec(
        name="direct_shade" + ("_polygons" if polygons else "") + ("_soft_sun" if soft_sun else "")
        + ("_atlas_centres" if area_samples == 1 else f"_atlas_area{area_samples}" if area else ""),
        compute="direct/shade.comp.glsl",
        local_size=(8, 8, 1),
        samplers=(Sampler("gbuf_position", "2D"), Sampler("gbuf_normal", "2D"), Sampler("rsm_position", "2D"),
                  Sampler("rsm_normal", "2D"))
        + ((Sampler("rsm_flux", "2D"), Sampler("occluders", "2D")) if exact else ())
        + ((Sampler("emitters", "2D"),) if polygons else ())
        + tuple(Sampler(name, "2D") for name in listed + footprint),
        images=(Image("direct", "2D", "RGBA32F", "read_write"),),
        uniforms=(
            Var("light_view_projection", "mat4"),
            Var("light_pos_ws", "vec3"), Var("texel_scale", "float"),
            Var("emit_axis", "vec3"), Var("light_kind", "int"),
            Var("light_color_intensity", "vec3"), Var("face_index", "int"),
            Var("spot_cos_half", "float"), Var("spot_blend", "float"), Var("shadow_bias_texels", "float"),
            Var("accumulate", "int"),
        ) + (() if polygons else (Var("exact_near_texels", "float"),))  # the exact tests': not a polygon's
        + (() if soft_sun else (Var("face_lift_share", "float"),))  # a lamp's faces' partition: no sun's
        + ((Var("poly_first", "int"), Var("poly_count", "int"), Var("emitter_radius_m", "float"),
               Var("light_view_projection_inverse", "mat4")) if polygons else ())
        + ((Var("sun_tan_half", "float"),) if soft_sun else ()),
        defines=((("POLYGONS", "1"),) if polygons else ())
        + ((("OCCLUDER_ROW", str(rsm.OCCLUDER_ROW)),) if exact else ()) + ((("SOFT_SUN", "1"),) if soft_sun else ())
        + ((("TEXEL_LIST", "1"),) if listed else ()) + ((("AREA_SAMPLES", str(area_samples)),) if area else ()),
    )


SPECS = {(polygons, soft_sun): _spec(polygons, soft_sun) for polygons in (False, True) for soft_sun in (False, True)}


DECL = PassDecl("direct_light", "gather", (GBUF_POSITION, GBUF_NORMAL, RSM_POSITION, RSM_NORMAL, RSM_FLUX, OCCLUDERS,
                                          LIGHT_VIEWS, EMITTERS),
                (DIRECT,),
                "one light face's shadow-mapped direct light, added")


def run(backend: Backend, gbuf_position, gbuf_normal, shadow: dict, direct, view: LightView,
        shadow_bias_texels: float, emitters, accumulate: bool = True, lists=(),
        exact_near_texels: float = CAMERA_NEAR_TEXELS) -> None:
    """`shadow`: the shadow map's "position", "normal" and "flux" textures (the RSM's, or a sun's own map)
    and the "occluders" table its flux names triangles in (rsm.occluder_table).
    `emitters`: the emitter table texture; the view's uniforms give its rows (poly_first, poly_count).
    accumulate: add to `direct`; False: replace its pixels that see geometry (those that see none are not
    written: the caller keeps them 0). lists: where the G-buffer is a probe atlas, the texels to shade
    instead of every pixel, as (texel list, samples, footprint textures by name) each: the list's texels
    shaded at `samples` points along their footprints (1: at their centres, no footprint needed).
    exact_near_texels: the exact shadow tests' margin (CAMERA_NEAR_TEXELS, SURFACE_NEAR_TEXELS)."""
    view_uniforms = view.uniforms
    soft_sun = view_uniforms["light_kind"] == KIND_CODE["SUN"] and view_uniforms["sun_tan_half"] > 0.0
    polygons = view_uniforms.get("poly_count", 0) > 0
    samplers = {"gbuf_position": gbuf_position, "gbuf_normal": gbuf_normal, "rsm_position": shadow["position"],
                "rsm_normal": shadow["normal"], "rsm_flux": shadow["flux"], "occluders": shadow["occluders"],
                "emitters": emitters}
    passes = [(_spec(polygons, soft_sun, samples), texels.size, {"texel_list": texels, **footprint})
              for texels, samples, footprint in lists] or [(_spec(polygons, soft_sun), direct.size, {})]
    for spec, size, more in passes:
        names = {u.name for u in spec.uniforms}
        uniforms = {k: v for k, v in view_uniforms.items() if k in names}
        uniforms["shadow_bias_texels"] = shadow_bias_texels
        uniforms["accumulate"] = int(accumulate)
        if not polygons:
            uniforms["exact_near_texels"] = exact_near_texels
        bound = {**samplers, **more}
        backend.dispatch(backend.program(spec), group_count(size, spec.local_size), uniforms=uniforms,
                         samplers={s.name: bound[s.name] for s in spec.samplers}, images={"direct": direct})
