"""Probe shading and SH projection (solve half, per light change; paper 004, eq. 3).

probe_direct: the direct pass (direct_light.run, the same shader and shadow test as the camera's) run
on the atlas G-buffer, one light face at a time: `atlas_direct` = irradiance / pi at every surface a
probe sees. probe_project: per probe (one invocation each, all 9 coefficients from one pass over its
texels), c_i = sum over its 6 n^2 texels of
albedo x (direct [+ indirect]) x Y_i(w) x dw, w a texel's centre direction, dw its exact solid angle
(probe_grid.texel_solid_angles): the L2 SH of the radiance arriving at the probe (W/m^2/sr), by
direction of arrival. probe_reproject adds the previous bounce's indirect (probe_lookup.BOUNCE_DECL), so
the N-th projection holds bounces 1..N. Output `sh` (RGBA32F, 9 nx x ny nz; probe_grid.py), rgb.
With the irradiance encoding, probe_convolve / probe_reconvolve write instead each probe's irradiance
cube map: E(n) = sum over its texels of L max(0, n . w) dw at IRRADIANCE_TEXELS^2 normals a face, in
the capture's tile layout (grid.tiled_size), W/m^2.
"""

from __future__ import annotations

from ..backends.base import Backend, Image, Sampler, ShaderSpec, Var, group_count
from ..probe_grid import ProbeGrid
from . import direct_light
from .declare import EMITTERS, LIGHT_VIEWS, RSM_NORMAL, RSM_POSITION, PassDecl, Port
from .light_views import LightView
from .probe_capture import (
    ATLAS_ALBEDO,
    ATLAS_NORMAL,
    ATLAS_POSITION,
    ATLAS_TEXELS,
    ATLAS_UNIFORMS,
    FOOTPRINT,
    GRAZING_TEXELS,
    grid_uniforms,
)
from .sky_light import SKY_BOUNDS, SKY_DEPTH, SKY_TABLE

ATLAS_DIRECT = Port("probes", "direct", "RGBA32F", "probe_atlas", "irradiance / pi at the surface a texel sees")
ATLAS_INDIRECT = Port("probes", "indirect", "RGBA32F", "probe_atlas",
                      "the previous bounce's indirect irradiance / pi there (probe_lookup.bounce)")
SH = Port("probes", "sh", "RGBA32F", "probes", "L2 SH of incoming radiance (W/m^2/sr), coefficient i at i nx + ix")

IRRADIANCE = Port("probes", "irradiance", "RGBA32F", "probe_atlas",
                  "irradiance (W/m^2) per probe at 6 m^2 normals (the irradiance encoding)")
IRRADIANCE_TEXELS = 4  # m: each face of a probe's irradiance cube map is m x m normals

SHADE_DECL = PassDecl("probe_direct", "solve", (ATLAS_POSITION, ATLAS_NORMAL, RSM_POSITION, RSM_NORMAL, LIGHT_VIEWS,
                                                EMITTERS, ATLAS_TEXELS, *FOOTPRINT, GRAZING_TEXELS),
                      (ATLAS_DIRECT,), "one light face's shadow-mapped direct light on the probe atlas, added")
ATLAS_SKY = Port("probes", "sky", "RGBA32F", "probe_atlas", "the sky's irradiance / pi at the surface a texel sees")
SKY_DECL = PassDecl("probe_sky", "solve", (ATLAS_POSITION, ATLAS_NORMAL, ATLAS_TEXELS, GRAZING_TEXELS, SKY_DEPTH,
                                           SKY_BOUNDS, SKY_TABLE),
                    (ATLAS_SKY,), "the sky's shadowed direct light on the probe atlas (sky_light.direct), kept "
                    "until the geometry or the sky's directions change")
SKY_COPY_DECL = PassDecl("probe_sky_copy", "solve", (ATLAS_SKY,), (ATLAS_DIRECT,),
                         "the kept sky light as the solve's first face on the atlas")
PROJECT_DECL = PassDecl("probe_project", "solve", (ATLAS_ALBEDO, ATLAS_DIRECT), (SH,),
                        "the atlas shaded and projected to L2 SH per probe (first bounce)")
REPROJECT_DECL = PassDecl("probe_reproject", "solve", (ATLAS_ALBEDO, ATLAS_DIRECT, ATLAS_INDIRECT), (SH,),
                          "the atlas re-shaded with the previous bounce and projected (bounces 2..N)")


CONVOLVE_DECL = PassDecl("probe_convolve", "solve", (ATLAS_ALBEDO, ATLAS_DIRECT), (IRRADIANCE,),
                         "the atlas shaded and convolved to irradiance cube maps (first bounce)")
RECONVOLVE_DECL = PassDecl("probe_reconvolve", "solve", (ATLAS_ALBEDO, ATLAS_DIRECT, ATLAS_INDIRECT), (IRRADIANCE,),
                           "the atlas re-shaded with the previous bounce and convolved (bounces 2..N)")


def _spec(bounce: bool, encoding: str = "sh") -> ShaderSpec:
    if encoding == "irradiance":
        return ShaderSpec(
            name="probe_convolve" + ("_bounce" if bounce else ""),
            compute="probes/convolve.comp.glsl",
            local_size=(3 * IRRADIANCE_TEXELS, 2 * IRRADIANCE_TEXELS, 1),  # one probe's tile a group
            samplers=(Sampler("atlas_albedo", "2D"), Sampler("atlas_direct", "2D"))
            + ((Sampler("atlas_indirect", "2D"),) if bounce else ()),
            images=(Image("irradiance", "2D", "RGBA32F", "write"),),
            uniforms=(*ATLAS_UNIFORMS, Var("irradiance_texels", "int")),
            defines=(("BOUNCE", "1"),) if bounce else (),
        )
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


SPECS = {(bounce, encoding): _spec(bounce, encoding) for bounce in (False, True) for encoding in ("sh", "irradiance")}


def shade(backend: Backend, atlas: dict, atlas_direct, shadow: dict, view: LightView, shadow_bias_texels: float,
          emitters, first: bool, texel_lists: dict, footprint: dict | None = None, area_samples: int = 1) -> None:
    """atlas_direct += one light face's direct light at the texels `texel_lists` (probe_capture.texel_lists)
    holds; the solve's first face (`first`) replaces the last solve's light instead (the texels no list
    holds see no geometry: the caller keeps them 0). With area_samples > 1 (ProbesConfig.area_samples)
    the grazing texels are shaded at that many points of their footprints (`footprint`:
    probe_capture.footprint's textures)."""
    lists = [(texel_lists[ATLAS_TEXELS.name], 1, {})]
    if area_samples > 1:
        lists.append((texel_lists[GRAZING_TEXELS.name], area_samples, footprint))
    direct_light.run(backend, atlas["position"], atlas["normal"], shadow, atlas_direct, view,
                     shadow_bias_texels, emitters, accumulate=not first, lists=lists)


def run(backend: Backend, atlas: dict, atlas_direct, sh, grid: ProbeGrid, atlas_indirect=None) -> None:
    """sh := the projection of albedo x (direct [+ atlas_indirect]) for every probe."""
    spec = SPECS[(atlas_indirect is not None, "sh")]
    _dispatch(backend, spec, atlas, atlas_direct, atlas_indirect, {"sh": sh}, grid.state_size,
              grid_uniforms(spec, grid))


def convolve(backend: Backend, atlas: dict, atlas_direct, irradiance, grid: ProbeGrid, atlas_indirect=None) -> None:
    """irradiance := every probe's irradiance cube map (IRRADIANCE_TEXELS a face, the capture's tile layout,
    grid.tiled_size) of albedo x (direct [+ atlas_indirect])."""
    spec = SPECS[(atlas_indirect is not None, "irradiance")]
    _dispatch(backend, spec, atlas, atlas_direct, atlas_indirect, {"irradiance": irradiance}, irradiance.size,
              {**grid_uniforms(spec, grid), "irradiance_texels": IRRADIANCE_TEXELS})


def _dispatch(backend, spec, atlas, atlas_direct, atlas_indirect, images, size, uniforms) -> None:
    samplers = {"atlas_albedo": atlas["albedo"], "atlas_direct": atlas_direct}
    if atlas_indirect is not None:
        samplers["atlas_indirect"] = atlas_indirect
    backend.dispatch(backend.program(spec), group_count(size, spec.local_size), uniforms=uniforms,
                     samplers=samplers, images=images)
