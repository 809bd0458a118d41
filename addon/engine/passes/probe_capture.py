"""Probe capture (setup half, once per geometry change): every probe's six faces rasterized into one
atlas G-buffer (the paper's key optimisation: later light changes only re-shade it), then per texel
the distance moments its Chebyshev visibility reads, and per probe whether it is inside geometry.

capture: for each probe and face, the scene's triangles drawn with the face's 90-degree view-projection
(probe_grid.face_view_projection) into that face's n x n viewport of the atlas (layout: probe_grid.py).
Outputs (RGBA32F, atlas): position (m, w = 1 where geometry), normal (towards the probe, w = +1 front
face / -1 back face), albedo (the bounce albedo, Scene.bounce_albedo; w = 1 where geometry); depth 32F.
moments: mean and mean square of the probe-to-surface distance over a (2 MOMENT_RADIUS + 1)^2 window
of the texel's face, distances clamped at MAX_DISTANCE_RATIO x spacing (directions without geometry
count as that).
classify: per probe, the share of its sphere (exact texel solid angles) that sees back faces; above
ProbesConfig.backface_share the probe is off (state.x = 0): it is inside something.
"""

from __future__ import annotations

import numpy as np

from ..backends.base import Backend, Image, Sampler, ShaderSpec, Var, group_count
from ..probe_grid import ProbeGrid, face_view_projection
from . import declare, zero
from .declare import TRIANGLES, PassDecl, Port

# Texels each side of the moments' window. 0: each texel's own distance; the variance comes from the
# lookup's bilinear blend of neighbouring texels alone. A 3 x 3 window (1) let a closed box's lit
# inside leak 0.75 x its mean light onto the ground outside (tests/hard, light in a closed box; 0.002
# at 0): at a silhouette the window mixes the near face with what lies behind it, and the variance
# that makes stops nothing.
MOMENT_RADIUS = 0
# Distances in the moments are clamped at this x spacing: beyond any receiver that reads the probe (the
# 8 probes around a point are within sqrt(3) spacings of it, plus the normal bias).
MAX_DISTANCE_RATIO = 2.0
NEAR_RATIO = 1e-3  # a face's near plane, x spacing: surfaces closer to a probe than that are not seen

# What probe.glsl reads of the grid: the atlas layout alone, and with the probes' positions. A spec
# declares only what its shader reads (Blender refuses a uniform the compiler optimised out).
ATLAS_UNIFORMS = (Var("probe_dims", "ivec3"), Var("face_texels", "int"), Var("tiles_per_row", "int"))
GRID_UNIFORMS = (Var("probe_first", "vec3"), Var("probe_spacing", "float"), *ATLAS_UNIFORMS)


def grid_uniforms(spec: ShaderSpec, grid: ProbeGrid) -> dict:
    """The grid's uniforms that `spec` declares."""
    names = {u.name for u in spec.uniforms}
    return {k: v for k, v in grid.uniforms().items() if k in names}


def _atlas(name, units):
    return Port("probes", name, "RGBA32F", "probe_atlas", units)


ATLAS = (_atlas("position", "world position (m) a probe texel sees, w = 1 where geometry"),
         _atlas("normal", "world normal towards the probe; w = +1 front face, -1 back face"),
         _atlas("albedo", "bounce albedo (linear; Scene.bounce_albedo), w = 1 where geometry"))
ATLAS_POSITION, ATLAS_NORMAL, ATLAS_ALBEDO = ATLAS
MOMENTS = _atlas("moments", "probe-to-surface distance: mean (m), mean square (m^2) over a texel window")
STATE = Port("probes", "state", "RGBA32F", "probes", "x: 1 probe on, 0 off (inside geometry); y: back-face share")
# Written by probe_relocate (ProbesConfig.relocate); all 0 without it.
OFFSET = Port("probes", "offset", "RGBA32F", "probes",
              "xyz: the probe's move off its grid position (m); w: 1 where the last relocation step moved it")

CAPTURE_DECL = PassDecl("probe_capture", "setup", (TRIANGLES,), ATLAS,
                        "every probe's six faces rasterized into the atlas G-buffer")
MOMENTS_DECL = PassDecl("probe_moments", "setup", (ATLAS_POSITION, ATLAS_NORMAL, OFFSET), (MOMENTS, STATE),
                        "distance moments per atlas texel; probes inside geometry switched off")
# With ProbesConfig.area_samples > 1: what the direct pass needs to shade a grazing texel along its
# footprint (probes/footprint.comp.glsl).
FOOTPRINT = (_atlas("footprint_origin", "xyz: the texel's probe position (m); w: the least distance to follow "
                    "its plane (m)"),
             _atlas("footprint_step", "xyz: the ray direction's change across the texel (0: it does not graze); "
                    "w: the greatest distance to follow its plane (m)"),
             _atlas("footprint_neighbours", "xy, zw: atlas offsets of the neighbours seen nearer and farther along "
                    "the footprint ((0, 0): none)"))
FOOTPRINT_DECL = PassDecl("probe_footprint", "setup", (ATLAS_POSITION, ATLAS_NORMAL, OFFSET), FOOTPRINT,
                          "per grazing atlas texel, its probe, footprint step and plane's distance range")
# The atlas texels the per-light passes shade, as lists: llvmpipe runs every branch of a compute shader
# for every invocation, so a texel that sees nothing still costs an invocation unless the dispatch
# leaves it out (5-10 % of the atlas passes; docs/PROBES.md, "What the light update costs").
ATLAS_TEXELS = Port("probes", "atlas_texels", "RGBA32F", "list",
                    "xy: an atlas texel that sees geometry and is shaded at its centre; w: 1 (0 past the list's end)")
GRAZING_TEXELS = Port("probes", "grazing_texels", "RGBA32F", "list",
                      "xy: an atlas texel whose footprint_step is not 0; w: 1 (0 past the list's end)")
TEXEL_LIST_WIDTH = 1024  # entries per row of a list of texels
LISTS_DECL = PassDecl("probe_texel_lists", "setup", (ATLAS_POSITION, FOOTPRINT[1]), (ATLAS_TEXELS, GRAZING_TEXELS),
                      "the atlas texels that see geometry (read back), apart from the grazing ones with area samples")

SPEC = ShaderSpec(
    name="probe_capture",
    vertex="probes/capture.vert.glsl",
    fragment="probes/capture.frag.glsl",
    uniforms=(Var("view_projection", "mat4"), Var("camera_pos_ws", "vec3")),
    attributes=(Var("pos_ws", "vec3"), Var("plane_ws", "vec4"), Var("normal_ws", "vec3"),
                Var("bounce_albedo", "vec3")),
    varyings=(Var("v_pos_ws", "vec3"), Var("v_plane_ws", "vec4", "flat"), Var("v_normal_ws", "vec3"),
              Var("v_albedo", "vec3")),
    outputs=(Var("out_position", "vec4"), Var("out_normal", "vec4"), Var("out_albedo", "vec4")),
)

MOMENTS_SPEC = ShaderSpec(
    name="probe_moments",
    compute="probes/moments.comp.glsl",
    local_size=(8, 8, 1),
    samplers=(Sampler("atlas_position", "2D"), Sampler("probe_offset", "2D")),
    images=(Image("moments", "2D", "RGBA32F", "write"),),
    uniforms=(*GRID_UNIFORMS, Var("max_distance_m", "float"), Var("moment_radius", "int")),
)

FOOTPRINT_SPEC = ShaderSpec(
    name="probe_footprint",
    compute="probes/footprint.comp.glsl",
    local_size=(8, 8, 1),
    samplers=(Sampler("atlas_position", "2D"), Sampler("atlas_normal", "2D"), Sampler("probe_offset", "2D")),
    images=tuple(Image(p.name, "2D", "RGBA32F", "write") for p in FOOTPRINT),
    uniforms=GRID_UNIFORMS,
)

CLASSIFY_SPEC = ShaderSpec(
    name="probe_classify",
    compute="probes/classify.comp.glsl",
    local_size=(8, 8, 1),
    samplers=(Sampler("atlas_normal", "2D"),),
    images=(Image("state", "2D", "RGBA32F", "write"),),
    uniforms=(*ATLAS_UNIFORMS, Var("backface_share", "float")),
)


def far_m(bounds_m) -> float:
    """Beyond every surface: the far plane of the faces."""
    lo, hi = (np.asarray(b, np.float64) for b in bounds_m)
    return 2.0 * float(np.linalg.norm(hi - lo)) + 1e-3


def face_matrices(grid: ProbeGrid, far: float, positions_m: np.ndarray | None = None) -> list[np.ndarray]:
    """The view-projection of every probe's faces, in probe order then face order, from the probes at
    `positions_m` ((count, 3); default their grid positions)."""
    near = NEAR_RATIO * grid.spacing_m
    centres = grid.positions_m() if positions_m is None else positions_m
    return [face_view_projection(c, f, near, far) for c in centres for f in range(6)]


def run(backend: Backend, target, atlas: dict, mesh, grid: ProbeGrid, matrices: list[np.ndarray],
        needed: np.ndarray | None = None, positions_m: np.ndarray | None = None) -> None:
    """Fill the atlas G-buffer (`atlas` = the ATLAS textures, attached to `target` with a depth) from the
    probes at `positions_m` (default: the grid's; `matrices` from the same positions); with `needed`
    ((count,) bool, ProbeGrid.read_by) only those probes' faces: the others' texels stay empty, so the
    per-light shading skips them too (it skips texels that see no geometry)."""
    zero.images(backend, [atlas[p.name] for p in ATLAS])
    draw(backend, target, mesh, grid, matrices, np.ones(grid.count, bool) if needed is None else needed,
         grid.positions_m() if positions_m is None else positions_m)


def draw(backend: Backend, target, mesh, grid: ProbeGrid, matrices: list[np.ndarray], probes: np.ndarray,
         positions_m: np.ndarray) -> None:
    """Draw the faces of the `probes` ((count,) bool) into their tiles, over what the tiles hold (run
    and relocation clear them first)."""
    backend.clear(target, color=None, depth=1.0)
    if mesh is None:
        return
    program = backend.program(SPEC)
    n = grid.face_texels
    for p in np.flatnonzero(probes):
        for f in range(6):
            x, y = grid.face_origin(p, f)
            backend.draw(program, target, mesh, depth_test=True, viewport=(x, y, n, n),
                         uniforms={"view_projection": matrices[6 * p + f], "camera_pos_ws": positions_m[p]})


def moments(backend: Backend, atlas: dict, out_moments, out_state, grid: ProbeGrid, backface_share: float,
            offset, needed: np.ndarray | None = None) -> None:
    """The distance moments (from each probe's position: its grid position + `offset`, the OFFSET
    texture) and the probes' state; probes not `needed` (not captured) are off."""
    backend.dispatch(backend.program(MOMENTS_SPEC), group_count(out_moments.size, MOMENTS_SPEC.local_size),
                     uniforms={**grid_uniforms(MOMENTS_SPEC, grid), "moment_radius": MOMENT_RADIUS,
                               "max_distance_m": MAX_DISTANCE_RATIO * grid.spacing_m},
                     samplers={"atlas_position": atlas["position"], "probe_offset": offset},
                     images={"moments": out_moments})
    backend.dispatch(backend.program(CLASSIFY_SPEC), group_count(out_state.size, CLASSIFY_SPEC.local_size),
                     uniforms={**grid_uniforms(CLASSIFY_SPEC, grid), "backface_share": backface_share},
                     samplers={"atlas_normal": atlas["normal"]}, images={"state": out_state})
    if needed is not None:  # state is (nx, ny nz): row iy + ny iz, column ix, as probe order ravels
        state = backend.read(out_state)
        state[..., 0] *= needed.reshape(state.shape[:2])
        backend.write(out_state, state)


def footprint(backend: Backend, atlas: dict, offset, grid: ProbeGrid) -> dict:
    """FOOTPRINT's textures by name: each grazing texel's footprint, from the capture and the probes'
    positions (grid + `offset`)."""
    out = declare.allocate(backend, FOOTPRINT, grid.atlas_size)
    backend.dispatch(backend.program(FOOTPRINT_SPEC), group_count(grid.atlas_size, FOOTPRINT_SPEC.local_size),
                     uniforms=grid_uniforms(FOOTPRINT_SPEC, grid),
                     samplers={"atlas_position": atlas["position"], "atlas_normal": atlas["normal"],
                               "probe_offset": offset},
                     images=out)
    return out


def texel_lists(backend: Backend, atlas: dict, footprint: dict | None) -> dict:
    """LISTS_DECL's lists by name: ATLAS_TEXELS, every atlas texel that sees geometry, and with a
    `footprint` (area samples) GRAZING_TEXELS, those of them that graze, which ATLAS_TEXELS then leaves
    out (the direct pass shades them apart, so that their loop runs only where they are)."""
    sees = backend.read(atlas["position"])[..., 3] != 0.0  # rows are texel rows y, from 0
    if footprint is None:
        return {ATLAS_TEXELS.name: texel_list(backend, sees)}
    grazing = np.any(backend.read(footprint["footprint_step"])[..., :3] != 0.0, axis=-1)
    return {ATLAS_TEXELS.name: texel_list(backend, sees & ~grazing),
            GRAZING_TEXELS.name: texel_list(backend, sees & grazing)}


def texel_list(backend: Backend, mask: np.ndarray):
    """The texels where `mask` ((h, w) bool) holds, as a texture TEXEL_LIST_WIDTH entries wide (one
    entry where there are none): xy the texel, w 1; entries past the list's end are 0."""
    y, x = np.nonzero(mask)
    width = int(min(TEXEL_LIST_WIDTH, max(len(x), 1)))
    table = np.zeros((-(-max(len(x), 1) // width) * width, 4), np.float32)
    table[:len(x)] = np.stack([x, y, np.zeros_like(x), np.ones_like(x)], axis=-1)
    return backend.texture((width, len(table) // width), data=table.reshape(-1, width, 4))
