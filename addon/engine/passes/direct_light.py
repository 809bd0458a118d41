"""Direct-light pass: shadow-mapped direct diffuse light of one light face at every G-buffer pixel.

Inputs: G-buffer position and normal, the face's RSM position and normal (shadow test), LightView
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
from .declare import (
    DIRECT,
    EMITTERS,
    GBUF_NORMAL,
    GBUF_POSITION,
    LIGHT_VIEWS,
    RSM_NORMAL,
    RSM_POSITION,
    PassDecl,
)
from .light_views import KIND_CODE, LightView


@functools.cache  # one spec, hence one program, per kind
def _spec(polygons: bool, soft_sun: bool, area_samples: int = 0) -> ShaderSpec:
    """The pass for one kind of light: with its polygons' irradiance (POLYGONS: the emitter table and
    its rows) or a point's, with a sun's soft shadows (SOFT_SUN: the sun's angle) or a hard shadow test.
    One program each, because llvmpipe runs the code of a branch no invocation takes: with both kinds in
    one program a spot's shading of the probe atlas took 4.5 x as long (docs/PROBES.md).
    The probe atlas shaded by its texels' areas (ProbesConfig.area_samples) takes two: area_samples 1,
    ATLAS_CENTRES, every texel but the grazing ones at its centre; area_samples > 1, AREA_SAMPLES, the
    listed grazing texels (`grazing_texels`) at that many points along their footprints
    (probe_capture.FOOTPRINT). Apart, so that the grazing texels' loop runs only where they are."""
    area = area_samples > 1
    footprint = ("footprint_step",) if area_samples == 1 else \
        ("footprint_origin", "footprint_step", "footprint_neighbours", "grazing_texels") if area else ()
    return ShaderSpec(
        name="direct_shade" + ("_polygons" if polygons else "") + ("_soft_sun" if soft_sun else "")
        + ("_atlas_centres" if area_samples == 1 else f"_atlas_area{area_samples}" if area else ""),
        compute="direct/shade.comp.glsl",
        local_size=(8, 8, 1),
        samplers=(Sampler("gbuf_position", "2D"), Sampler("gbuf_normal", "2D"), Sampler("rsm_position", "2D"),
                  Sampler("rsm_normal", "2D"))
        + ((Sampler("emitters", "2D"),) if polygons else ()) + tuple(Sampler(name, "2D") for name in footprint),
        images=(Image("direct", "2D", "RGBA32F", "read_write"),),
        uniforms=(
            Var("light_view_projection", "mat4"),
            Var("light_pos_ws", "vec3"), Var("texel_scale", "float"),
            Var("emit_axis", "vec3"), Var("light_kind", "int"),
            Var("light_color_intensity", "vec3"), Var("face_index", "int"),
            Var("spot_cos_half", "float"), Var("spot_blend", "float"), Var("shadow_bias_texels", "float"),
            Var("accumulate", "int"),
        ) + ((Var("poly_first", "int"), Var("poly_count", "int"), Var("emitter_radius_m", "float"),
               Var("light_view_projection_inverse", "mat4")) if polygons else ())
        + ((Var("sun_tan_half", "float"),) if soft_sun else ()),
        defines=((("POLYGONS", "1"),) if polygons else ()) + ((("SOFT_SUN", "1"),) if soft_sun else ())
        + ((("ATLAS_CENTRES", "1"),) if area_samples == 1 else (("AREA_SAMPLES", str(area_samples)),) if area else ()),
    )


SPECS = {(polygons, soft_sun): _spec(polygons, soft_sun) for polygons in (False, True) for soft_sun in (False, True)}


DECL = PassDecl("direct_light", "gather", (GBUF_POSITION, GBUF_NORMAL, RSM_POSITION, RSM_NORMAL, LIGHT_VIEWS, EMITTERS),
                (DIRECT,),
                "one light face's shadow-mapped direct light, added")


def run(backend: Backend, gbuf_position, gbuf_normal, shadow: dict, direct, view: LightView,
        shadow_bias_texels: float, emitters, accumulate: bool = True, footprint=None) -> None:
    """`shadow`: the shadow map's "position" and "normal" textures (the RSM's, or a sun's own map).
    `emitters`: the emitter table texture; the view's uniforms give its rows (poly_first, poly_count).
    accumulate: add to `direct`; False: replace its pixels that see geometry (those that see none are not
    written: the caller keeps them 0). footprint: where the G-buffer is a probe atlas to shade by its
    texels' areas, (probe_capture.footprint's textures by name with the grazing texels' list, samples):
    the texels that do not graze at their centres, then the listed ones along their footprints."""
    view_uniforms = view.uniforms
    soft_sun = view_uniforms["light_kind"] == KIND_CODE["SUN"] and view_uniforms["sun_tan_half"] > 0.0
    polygons = view_uniforms.get("poly_count", 0) > 0
    samplers = {"gbuf_position": gbuf_position, "gbuf_normal": gbuf_normal, "rsm_position": shadow["position"],
                "rsm_normal": shadow["normal"], "emitters": emitters}
    if footprint is None:
        passes = ((_spec(polygons, soft_sun), direct.size),)
    else:
        textures, samples = footprint
        samplers.update(textures)
        passes = ((_spec(polygons, soft_sun, 1), direct.size),
                  (_spec(polygons, soft_sun, samples), textures["grazing_texels"].size))
    for spec, size in passes:
        names = {u.name for u in spec.uniforms}
        uniforms = {k: v for k, v in view_uniforms.items() if k in names}
        uniforms["shadow_bias_texels"] = shadow_bias_texels
        uniforms["accumulate"] = int(accumulate)
        backend.dispatch(backend.program(spec), group_count(size, spec.local_size), uniforms=uniforms,
                         samplers={s.name: samplers[s.name] for s in spec.samplers}, images={"direct": direct})
