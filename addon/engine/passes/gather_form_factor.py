"""The final gather of method `gather` (gather half: camera pixels or lightmap texels; paper 001,
docs/GATHER.md; gpu_shaders/gather/form_factor.comp.glsl has the formulas).

At each G-buffer texel x with normal n, for each of the 8 probes around it (weighted and renormalised
as the probes' lookup weighs them: trilinear x back-face x Chebyshev visibility, probes/weights.glsl),
every quad light of the probe (gather_quads) is rebuilt in world space at its measured corner
distances and adds L F: F the polygon-to-point form factor (Lambert's formula, the quad clipped to x's
horizon; bounded by 1 however close x lies to it) or, with GatherConfig.form_factor = "point", the
paper's baseline A cos cos / (pi r^2) to its centre. sum L F = E / pi: Cycles' Diffuse Indirect.
Output: indirect (RGBA32F, written; alpha 0).
"""

from __future__ import annotations

from ..backends.base import Backend, Image, Sampler, ShaderSpec, Var, group_count
from ..config import GatherConfig, ProbesConfig
from ..probe_grid import ProbeGrid
from .declare import GBUF_NORMAL, GBUF_POSITION, INDIRECT, PassDecl
from .gather_quads import FINE_PLANE, FINE_RADIANCE, QUAD_CORNERS, QUAD_RADIANCE
from .probe_capture import GRID_UNIFORMS, MOMENTS, OFFSET, STATE
from .probe_lookup import MIN_VARIANCE_RATIO
from .rsm_gather import MAX_LOOP_ITERATIONS

DECL = PassDecl("gather_form_factor", "gather",
                (GBUF_POSITION, GBUF_NORMAL, QUAD_RADIANCE, QUAD_CORNERS, FINE_RADIANCE, FINE_PLANE, MOMENTS, STATE,
                 OFFSET),
                (INDIRECT,), "every probe's quad lights around each pixel, by their form factors")

ITEMS = 48  # (probe, face) pairs a receiver visits: 8 probes x 6 faces


def _spec(form_factor: str) -> ShaderSpec:
    return ShaderSpec(
        name="gather_form_factor" + ("_point" if form_factor == "point" else ""),
        compute="gather/form_factor.comp.glsl",
        local_size=(8, 8, 1),
        samplers=(Sampler("gbuf_position", "2D"), Sampler("gbuf_normal", "2D"), Sampler("quad_radiance", "2D"),
                  Sampler("quad_corners", "2D"), Sampler("fine_radiance", "2D"), Sampler("fine_plane", "2D"),
                  Sampler("moments", "2D"), Sampler("state", "2D"), Sampler("probe_offset", "2D")),
        images=(Image("indirect", "2D", "RGBA32F", "read_write"),),
        uniforms=(*GRID_UNIFORMS, Var("normal_bias_m", "float"), Var("min_variance_m2", "float"),
                  Var("visibility", "int"), Var("face_quads", "int"), Var("item_begin", "int"),
                  Var("item_end", "int")),
        defines=(("POINT_FORM_FACTOR", "1"),) if form_factor == "point" else (),
    )


SPECS = {form_factor: _spec(form_factor) for form_factor in ("polygon", "point")}


def items_per_dispatch(face_texels: int, face_quads: int) -> int:
    """(probe, face) pairs per dispatch so that no invocation loops more than MAX_LOOP_ITERATIONS times
    (llvmpipe's cap, FACTS.md): a face costs at most its M^2 quads plus, where every quad is split, its
    n^2 texels, each up to 4 clipping and 5 edge iterations."""
    per_item = (face_quads ** 2 + face_texels ** 2) * 10
    return max(1, min(ITEMS, MAX_LOOP_ITERATIONS // per_item))


def run(backend: Backend, position, normal, quads: dict, moments, state, offset, indirect, grid: ProbeGrid,
        probes: ProbesConfig, config: GatherConfig) -> None:
    """indirect := the quad lights of the probes around every texel of the G-buffer `position` / `normal`
    (`quads`: the gather_quads textures by port name; `offset`: the probes' relocation, OFFSET)."""
    spec = SPECS[config.form_factor]
    uniforms = {**grid.uniforms(), "normal_bias_m": probes.normal_bias * grid.spacing_m,
                "min_variance_m2": MIN_VARIANCE_RATIO * grid.spacing_m ** 2,
                "visibility": int(probes.chebyshev_visibility), "face_quads": config.face_quads}
    samplers = {"gbuf_position": position, "gbuf_normal": normal, "moments": moments, "state": state,
                "probe_offset": offset,
                **{k: quads[k] for k in ("quad_radiance", "quad_corners", "fine_radiance", "fine_plane")}}
    step = items_per_dispatch(grid.face_texels, config.face_quads)
    for begin in range(0, ITEMS, step):
        backend.dispatch(backend.program(spec), group_count(indirect.size, spec.local_size),
                         uniforms={**uniforms, "item_begin": begin, "item_end": min(begin + step, ITEMS)},
                         samplers=samplers, images={"indirect": indirect})
