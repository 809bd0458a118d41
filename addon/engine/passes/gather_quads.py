"""The quad lights of method `gather` (solve half, per light change; paper 001, Umenhoffer &
Szirmay-Kalos, "Robust diffuse final gathering on the GPU"; docs/GATHER.md).

gather_texels: per texel of the probes' atlas (probe_capture: every probe's six n x n faces), the
radiance it brings, L = albedo x (direct [+ the previous bounces' indirect]) (W/m^2/sr; the same
radiance the probes project, probes/radiance.glsl), and the plane of the surface it sees (its normal
and offset from the probe): where the surface is flat, that plane cut by the texel's four corner
directions is exactly the piece of it the texel sees (gather/quad.glsl, plane_corner; a plane seen
near edge-on is cut at 4 x the texel's distance, in the plane).
gather_quads: each face's texels merged into M x M quads (GatherConfig.face_quads = M, dividing n),
each a quad light whose radiance is the solid-angle-weighted mean of its texels' and whose corners lie
at the mean of the distances at which the planes of the texels touching each corner meet its direction
(on every cube face that holds the corner: a quad shares its corners with its neighbours across cube
edges, no seams). A quad over a depth edge (two planes meeting a corner's direction more than 10 %
apart), over directions that see nothing or over a plane seen near edge-on is marked for the gather to
use its texels one by one instead: averaged, it would float between the near and the far surface (the
digest's pitfall).
Outputs: fine_radiance, fine_plane (atlas, n x n faces); quad_radiance (rgb; a = 0 none, 1 one quad,
2 its texels), quad_corners (the capture's tile layout with M x M faces, grid.tiled_size(M)).
"""

from __future__ import annotations

from ..backends.base import Backend, Image, Sampler, ShaderSpec, Var, group_count
from ..probe_grid import ProbeGrid
from .declare import PassDecl, Port
from .probe_capture import (
    ATLAS_ALBEDO,
    ATLAS_NORMAL,
    ATLAS_POSITION,
    ATLAS_UNIFORMS,
    GRID_UNIFORMS,
    OFFSET,
    grid_uniforms,
)
from .probe_project import ATLAS_DIRECT, ATLAS_INDIRECT

FINE_RADIANCE = Port("gather", "fine_radiance", "RGBA32F", "probe_atlas",
                     "radiance (W/m^2/sr) a probe texel brings; w = 1 where it sees geometry")
FINE_PLANE = Port("gather", "fine_plane", "RGBA32F", "probe_atlas",
                  "plane of the surface a probe texel sees: unit normal towards the probe, offset n . (x - probe) (m)")
QUAD_RADIANCE = Port("gather", "quad_radiance", "RGBA32F", "probe_quads",
                     "mean radiance (W/m^2/sr) of a quad's texels; a = 0 none, 1 whole quad, 2 its texels")
QUAD_CORNERS = Port("gather", "quad_corners", "RGBA32F", "probe_quads",
                    "distance (m) from the probe to a whole quad's 4 corners")

TEXELS_DECL = PassDecl("gather_texels", "solve", (ATLAS_POSITION, ATLAS_NORMAL, ATLAS_ALBEDO, ATLAS_DIRECT,
                                                   ATLAS_INDIRECT, OFFSET),
                       (FINE_RADIANCE, FINE_PLANE), "each probe texel's radiance and its surface's plane")
QUADS_DECL = PassDecl("gather_quads", "solve", (FINE_RADIANCE, FINE_PLANE), (QUAD_RADIANCE, QUAD_CORNERS),
                      "each probe face's texels merged into M x M quad lights (split over depth edges)")


def _texels_spec(bounce: bool) -> ShaderSpec:
    return ShaderSpec(
        name="gather_texels" + ("_bounce" if bounce else ""),
        compute="gather/texels.comp.glsl",
        local_size=(8, 8, 1),
        samplers=(Sampler("atlas_position", "2D"), Sampler("atlas_normal", "2D"), Sampler("atlas_albedo", "2D"),
                  Sampler("atlas_direct", "2D"), Sampler("probe_offset", "2D"))
        + ((Sampler("atlas_indirect", "2D"),) if bounce else ()),
        images=(Image("fine_radiance", "2D", "RGBA32F", "write"), Image("fine_plane", "2D", "RGBA32F", "write")),
        uniforms=GRID_UNIFORMS,
        defines=(("BOUNCE", "1"),) if bounce else (),
    )


TEXELS_SPECS = {bounce: _texels_spec(bounce) for bounce in (False, True)}

QUADS_SPEC = ShaderSpec(
    name="gather_quads",
    compute="gather/quads.comp.glsl",
    local_size=(8, 8, 1),
    samplers=(Sampler("fine_radiance", "2D"), Sampler("fine_plane", "2D")),
    images=(Image("quad_radiance", "2D", "RGBA32F", "write"), Image("quad_corners", "2D", "RGBA32F", "write")),
    uniforms=(*ATLAS_UNIFORMS, Var("face_quads", "int")),
)


def allocate(backend: Backend, grid: ProbeGrid, face_quads: int) -> dict:
    """The textures both passes write: {port name: texture}."""
    fine, quads = grid.atlas_size, grid.tiled_size(face_quads)
    return {FINE_RADIANCE.name: backend.texture(fine), FINE_PLANE.name: backend.texture(fine),
            QUAD_RADIANCE.name: backend.texture(quads), QUAD_CORNERS.name: backend.texture(quads)}


def texels(backend: Backend, atlas: dict, atlas_direct, out: dict, grid: ProbeGrid, offset,
           atlas_indirect=None) -> None:
    """out["fine_radiance"], out["fine_plane"] := every atlas texel's radiance (albedo x (direct
    [+ atlas_indirect])) and the plane of the surface it sees, relative to its probe (at its grid position
    + `offset`, the OFFSET texture)."""
    spec = TEXELS_SPECS[atlas_indirect is not None]
    samplers = {"atlas_position": atlas["position"], "atlas_normal": atlas["normal"], "atlas_albedo": atlas["albedo"],
                "atlas_direct": atlas_direct, "probe_offset": offset}
    if atlas_indirect is not None:
        samplers["atlas_indirect"] = atlas_indirect
    backend.dispatch(backend.program(spec), group_count(grid.atlas_size, spec.local_size),
                     uniforms=grid_uniforms(spec, grid), samplers=samplers,
                     images={k: out[k] for k in ("fine_radiance", "fine_plane")})


def quads(backend: Backend, out: dict, grid: ProbeGrid, face_quads: int) -> None:
    """out["quad_radiance"], out["quad_corners"] := every probe face's M x M quads (M = face_quads)."""
    backend.dispatch(backend.program(QUADS_SPEC), group_count(grid.tiled_size(face_quads), QUADS_SPEC.local_size),
                     uniforms={**grid_uniforms(QUADS_SPEC, grid), "face_quads": face_quads},
                     samplers={k: out[k] for k in ("fine_radiance", "fine_plane")},
                     images={k: out[k] for k in ("quad_radiance", "quad_corners")})
