"""Reflective shadow map pass (Dachsbacher & Stamminger 2005): the scene seen from one light face.

Inputs: scene triangles (pos_ws, plane_ws (methods/direct.face_planes: which side the light sees),
normal_ws, bounce_albedo, and a Base Color texture's albedo_rect and albedo_uv: passes/albedo_atlas.py),
the albedo atlas (sampler), a LightView
(light_views.py). Outputs (RGBA32F, resolution^2, GL row 0 = bottom): position (world, m; w = 1 where
geometry), normal (world, flipped where the light sees its triangle's back), flux (W reflected by the
texel's surfel: albedo x I(w) x texel solid angle, or albedo x sun irradiance x texel area; the albedo
the texel under the texel's centre times bounce_albedo on a textured triangle, which holds the
texels' factor there, else bounce_albedo). The flux sums to the light's reflected power (tested against
the analytic cone integral). With Light.occluder_radius_m (an emissive mesh's lamp: the emitter's own
surface) the flux is reduced by the view factor from the surfel to that disc,
light_views.disc_view_factor: what the surfel sends back at the emitter stops there.
"""

from __future__ import annotations

import numpy as np

from ..backends.base import Backend, Sampler, ShaderSpec, Texture, Var
from .declare import ALBEDO_ATLAS, LIGHT_VIEWS, RSM, TRIANGLES, PassDecl
from .light_views import LightView

SPEC = ShaderSpec(
    name="rsm",
    vertex="rsm/rsm.vert.glsl",
    fragment="rsm/rsm.frag.glsl",
    uniforms=(
        Var("light_view_projection", "mat4"),
        Var("light_pos_ws", "vec3"), Var("texel_scale", "float"),
        Var("face_axis", "vec3"), Var("light_kind", "int"),
        Var("emit_axis", "vec3"), Var("spot_cos_half", "float"),
        Var("light_color_intensity", "vec3"), Var("spot_blend", "float"),
        Var("occluder_radius", "float"), Var("area_weight", "float"),
    ),
    samplers=(Sampler("albedo_atlas", "2D"),),
    attributes=(Var("pos_ws", "vec3"), Var("plane_ws", "vec4"), Var("normal_ws", "vec3"),
                Var("bounce_albedo", "vec3"), Var("albedo_rect", "vec4"), Var("albedo_uv", "vec2")),
    varyings=(Var("v_pos_ws", "vec3"), Var("v_plane_ws", "vec4", "flat"), Var("v_normal_ws", "vec3"),
              Var("v_albedo", "vec3"), Var("v_albedo_rect", "vec4", "flat"), Var("v_albedo_uv", "vec2")),
    outputs=(Var("out_position", "vec4"), Var("out_normal", "vec4"), Var("out_flux", "vec4")),
)


OCCLUDER_ROW = 1024  # triangles per row of the occluder table (3 texels each: 3072 wide, within GL's 16384)


def occluder_table(positions_m: np.ndarray) -> np.ndarray:
    """The corners (n, 3, 3) of the triangles an RSM draws, in draw order, as a (rows, 3 OCCLUDER_ROW, 4)
    RGBA32F table: triangle t's corner k at texel (3 (t % OCCLUDER_ROW) + k, t // OCCLUDER_ROW), the
    triangle its texels name (flux.w - 1)."""
    n = len(positions_m)
    rows = max(1, -(-n // OCCLUDER_ROW))
    table = np.zeros((rows * OCCLUDER_ROW * 3, 4), np.float32)
    table[:n * 3, :3] = np.asarray(positions_m, np.float32).reshape(-1, 3)
    return table.reshape(rows, OCCLUDER_ROW * 3, 4)


DECL = PassDecl("rsm", "solve", (TRIANGLES, ALBEDO_ATLAS, LIGHT_VIEWS), RSM, "the scene seen from one light face")


def run(backend: Backend, target, mesh, view: LightView, albedo_atlas: Texture) -> None:
    """The RSM of `view` into `target`, cleared first; `albedo_atlas` from albedo_atlas.upload."""
    backend.clear(target, color=(0, 0, 0, 0), depth=1.0)
    draw(backend, target, mesh, view, albedo_atlas)


def draw(backend: Backend, target, mesh, view: LightView, albedo_atlas: Texture, viewport=None) -> None:
    """The RSM of `view` over what `target` holds, into `viewport` (x, y, w, h; None: all of it), e.g. a
    tile of an atlas of several views (sky_light.rsm_tiles)."""
    if mesh is not None:
        names = {u.name for u in SPEC.uniforms}
        backend.draw(backend.program(SPEC), target, mesh,
                     uniforms={k: v for k, v in view.uniforms.items() if k in names},
                     samplers={"albedo_atlas": albedo_atlas}, depth_test=True, viewport=viewport)
