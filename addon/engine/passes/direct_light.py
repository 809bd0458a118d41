"""Direct-light pass: shadow-mapped direct diffuse light of one light face at every G-buffer pixel.

Inputs: G-buffer position and normal, the face's RSM position (shadow test), LightView uniforms, and
the emitter table (area_light.emitter_table): a light with polygons (poly_count > 0: an area light's
patch, an emissive mesh's triangles) gives the exact unshadowed irradiance of its shape, shadowed from
its position; the others are points (spots masked, area lights without a size Lambertian).
Output: `direct` (RGBA32F, camera resolution), accumulated over faces and lights, in the unit of
Cycles' Diffuse Direct pass: irradiance / pi. Point-light faces split directions by major axis, so
each pixel is shaded by exactly one face.
"""

from __future__ import annotations

from ..backends.base import Backend, Image, Sampler, ShaderSpec, Var, group_count
from .declare import DIRECT, EMITTERS, GBUF_NORMAL, GBUF_POSITION, LIGHT_VIEWS, RSM_POSITION, PassDecl
from .light_views import LightView

SPEC = ShaderSpec(
    name="direct_shade",
    compute="direct/shade.comp.glsl",
    local_size=(8, 8, 1),
    samplers=(Sampler("gbuf_position", "2D"), Sampler("gbuf_normal", "2D"), Sampler("rsm_position", "2D"),
              Sampler("emitters", "2D")),
    images=(Image("direct", "2D", "RGBA32F", "read_write"),),
    uniforms=(
        Var("light_view_projection", "mat4"),
        Var("light_pos_ws", "vec3"), Var("texel_scale", "float"),
        Var("emit_axis", "vec3"), Var("light_kind", "int"),
        Var("light_color_intensity", "vec3"), Var("face_index", "int"),
        Var("spot_cos_half", "float"), Var("spot_blend", "float"), Var("shadow_bias_texels", "float"),
        Var("poly_first", "int"), Var("poly_count", "int"), Var("sun_tan_half", "float"),
    ),
)


DECL = PassDecl("direct_light", "gather", (GBUF_POSITION, GBUF_NORMAL, RSM_POSITION, LIGHT_VIEWS, EMITTERS), (DIRECT,),
                "one light face's shadow-mapped direct light, added")


def run(backend: Backend, gbuf_position, gbuf_normal, rsm_position, direct, view: LightView,
        shadow_bias_texels: float, emitters) -> None:
    """`emitters`: the emitter table texture; the view's uniforms give its rows (poly_first, poly_count)."""
    names = {u.name for u in SPEC.uniforms}
    uniforms = {"poly_first": 0, "poly_count": 0, **{k: v for k, v in view.uniforms.items() if k in names}}
    uniforms["shadow_bias_texels"] = shadow_bias_texels
    backend.dispatch(backend.program(SPEC), group_count(direct.size, SPEC.local_size), uniforms=uniforms,
                     samplers={"gbuf_position": gbuf_position, "gbuf_normal": gbuf_normal,
                               "rsm_position": rsm_position, "emitters": emitters},
                     images={"direct": direct})
