"""Probe lookup (gather half; also the bounces of the solve): the 8 probes around each G-buffer texel,
weighted by trilinear x back-face x Chebyshev visibility from their distance moments, renormalised,
each probe's L2 SH convolved with the clamped cosine about the normal and clamped at 0, or with the
irradiance encoding its irradiance map read at the normal (DDGI's weighting of paper 004's
interpolation; gpu_shaders/probes/lookup.comp.glsl has the formulas).

Output: E / pi, Cycles' Diffuse Indirect (RGBA32F, written). `run` reads a camera or lightmap G-buffer
into `indirect`; `bounce` reads the probes' own atlas into `atlas_indirect`, which the next
projection adds to the direct light (probe_project.REPROJECT_DECL).
"""

from __future__ import annotations

from ..backends.base import Backend, Image, Sampler, ShaderSpec, Var, group_count
from ..config import ProbesConfig
from ..probe_grid import ProbeGrid
from .declare import GBUF_NORMAL, GBUF_POSITION, INDIRECT, PassDecl
from .probe_capture import ATLAS_NORMAL, ATLAS_POSITION, GRID_UNIFORMS, MOMENTS, OFFSET, STATE
from .probe_project import ATLAS_INDIRECT, IRRADIANCE, IRRADIANCE_TEXELS, SH

# The Chebyshev test's variance floor, x spacing^2: a flat wall seen head-on has almost no variance in
# its window, and float rounding alone must not hide a receiver lying on the wall the probe sees.
MIN_VARIANCE_RATIO = 4e-4

DECL = PassDecl("probe_lookup", "gather", (GBUF_POSITION, GBUF_NORMAL, SH, MOMENTS, STATE, OFFSET), (INDIRECT,),
                "the 8 surrounding probes read at every pixel, visibility-weighted")
BOUNCE_DECL = PassDecl("probe_bounce", "solve", (ATLAS_POSITION, ATLAS_NORMAL, SH, MOMENTS, STATE, OFFSET),
                       (ATLAS_INDIRECT,), "the probe field read at every atlas texel: the next bounce's source")
# The same passes with the irradiance encoding (ProbesConfig.encoding): cube maps instead of SH.
IRRADIANCE_DECL = PassDecl("probe_lookup", "gather",
                           (GBUF_POSITION, GBUF_NORMAL, IRRADIANCE, MOMENTS, STATE, OFFSET),
                           (INDIRECT,), "the 8 surrounding probes' irradiance maps read at every pixel")
IRRADIANCE_BOUNCE_DECL = PassDecl("probe_bounce", "solve",
                                  (ATLAS_POSITION, ATLAS_NORMAL, IRRADIANCE, MOMENTS, STATE, OFFSET),
                                  (ATLAS_INDIRECT,), "the irradiance maps read at every atlas texel")


def _spec(encoding: str) -> ShaderSpec:
    irradiance = encoding == "irradiance"
    return ShaderSpec(
        name="probe_lookup" + ("_irradiance" if irradiance else ""),
        compute="probes/lookup.comp.glsl",
        local_size=(8, 8, 1),
        samplers=(Sampler("gbuf_position", "2D"), Sampler("gbuf_normal", "2D"),
                  Sampler("irradiance" if irradiance else "sh", "2D"), Sampler("moments", "2D"),
                  Sampler("state", "2D"), Sampler("probe_offset", "2D")),
        images=(Image("indirect", "2D", "RGBA32F", "write"),),
        uniforms=(*GRID_UNIFORMS, Var("normal_bias_m", "float"), Var("min_variance_m2", "float"),
                  Var("visibility", "int")) + ((Var("irradiance_texels", "int"),) if irradiance else ()),
        defines=(("IRRADIANCE", "1"),) if irradiance else (),
    )


SPECS = {encoding: _spec(encoding) for encoding in ("sh", "irradiance")}


def run(backend: Backend, position, normal, field: dict, indirect, grid: ProbeGrid, config: ProbesConfig) -> None:
    """indirect := the probe field (`field`: sh or irradiance, moments, state, probe_offset) read at every texel of the
    G-buffer `position` / `normal` (a camera's, a lightmap's, or the probe atlas's for a bounce)."""
    irradiance = "irradiance" in field
    uniforms = {**grid.uniforms(), "normal_bias_m": config.normal_bias * grid.spacing_m,
                "min_variance_m2": MIN_VARIANCE_RATIO * grid.spacing_m ** 2,
                "visibility": int(config.chebyshev_visibility)}
    if irradiance:
        uniforms["irradiance_texels"] = IRRADIANCE_TEXELS
    spec = SPECS["irradiance" if irradiance else "sh"]
    backend.dispatch(backend.program(spec), group_count(indirect.size, spec.local_size), uniforms=uniforms,
                     samplers={"gbuf_position": position, "gbuf_normal": normal, **field},
                     images={"indirect": indirect})
