"""Probe shading and SH projection (solve half, per light change; paper 004, eq. 3).

probe_direct: the direct pass (direct_light.run, the same shader and shadow test as the camera's) run
on the atlas G-buffer, one light face at a time: `atlas_direct` = irradiance / pi at every surface a
probe sees. probe_project: per probe (one invocation each, all 9 coefficients from one pass over its
texels), c_i = sum over its 6 n^2 texels of
albedo x (direct [+ indirect]) x Y_i(w) x dw, w a texel's centre direction, dw its exact solid angle
(probe_grid.texel_solid_angles): the L2 SH of the radiance arriving at the probe (W/m^2/sr), by
direction of arrival. probe_reproject adds the previous bounce's indirect (probe_lookup.bounce), so the
N-th projection holds bounces 1..N. Output `sh` (RGBA32F, 9 nx x ny nz; probe_grid.py), rgb.
"""

from __future__ import annotations

from ..backends.base import Backend, Image, Sampler, ShaderSpec, group_count
from ..probe_grid import ProbeGrid
from . import direct_light
from .declare import EMITTERS, LIGHT_VIEWS, RSM_POSITION, PassDecl, Port
from .light_views import LightView
from .probe_capture import ATLAS_ALBEDO, ATLAS_NORMAL, ATLAS_POSITION, ATLAS_UNIFORMS, grid_uniforms

ATLAS_DIRECT = Port("probes", "direct", "RGBA32F", "probe_atlas", "irradiance / pi at the surface a texel sees")
ATLAS_INDIRECT = Port("probes", "indirect", "RGBA32F", "probe_atlas",
                      "the previous bounce's indirect irradiance / pi there (probe_lookup.bounce)")
SH = Port("probes", "sh", "RGBA32F", "probes", "L2 SH of incoming radiance (W/m^2/sr), coefficient i at i nx + ix")

SHADE_DECL = PassDecl("probe_direct", "solve", (ATLAS_POSITION, ATLAS_NORMAL, RSM_POSITION, LIGHT_VIEWS, EMITTERS),
                      (ATLAS_DIRECT,), "one light face's shadow-mapped direct light on the probe atlas, added")
PROJECT_DECL = PassDecl("probe_project", "solve", (ATLAS_ALBEDO, ATLAS_DIRECT), (SH,),
                        "the atlas shaded and projected to L2 SH per probe (first bounce)")
REPROJECT_DECL = PassDecl("probe_reproject", "solve", (ATLAS_ALBEDO, ATLAS_DIRECT, ATLAS_INDIRECT), (SH,),
                          "the atlas re-shaded with the previous bounce and projected (bounces 2..N)")


def _spec(bounce: bool) -> ShaderSpec:
    return ShaderSpec(
        name="probe_project" + ("_bounce" if bounce else ""),
        compute="probes/project.comp.glsl",
        local_size=(8, 8, 1),
        samplers=(Sampler("atlas_albedo", "2D"), Sampler("atlas_direct", "2D"))
        + ((Sampler("atlas_indirect", "2D"),) if bounce else ()),
        images=(Image("sh", "2D", "RGBA32F", "write"),),
        uniforms=ATLAS_UNIFORMS,
        defines=(("BOUNCE", "1"),) if bounce else (),
    )


SPECS = {bounce: _spec(bounce) for bounce in (False, True)}


def shade(backend: Backend, atlas: dict, atlas_direct, rsm_position, view: LightView, shadow_bias_texels: float,
          emitters) -> None:
    """atlas_direct += one light face's direct light (zeroed by the caller before the first face)."""
    direct_light.run(backend, atlas["position"], atlas["normal"], rsm_position, atlas_direct, view,
                     shadow_bias_texels, emitters)


def run(backend: Backend, atlas: dict, atlas_direct, sh, grid: ProbeGrid, atlas_indirect=None) -> None:
    """sh := the projection of albedo x (direct [+ atlas_indirect]) for every probe."""
    spec = SPECS[atlas_indirect is not None]
    samplers = {"atlas_albedo": atlas["albedo"], "atlas_direct": atlas_direct}
    if atlas_indirect is not None:
        samplers["atlas_indirect"] = atlas_indirect
    backend.dispatch(backend.program(spec), group_count(grid.state_size, spec.local_size),
                     uniforms=grid_uniforms(spec, grid),
                     samplers=samplers, images={"sh": sh})
