"""Probe relocation (setup half, ProbesConfig.relocate; docs/PROBES.md, "Relocation"): DDGI's idea
(Majercik et al. 2019, probe relocation) with this rule. From each probe's own capture, a probe inside
a solid moves out through the nearest back face and a probe near surfaces moves off them, within
RELOCATE_MAX_OFFSET_RATIO of the spacing per axis so it stays in the half cells around its grid position;
the probes that moved are captured again. The lookup's trilinear weights stay those of the grid
positions; everything geometric (the direction to the probe, the Chebyshev distances, the moments' own
distances) uses the moved positions (probe.glsl, probe_position).

step: per probe, gpu_shaders/probes/relocate.comp.glsl (the numpy twin: probe_grid.relocation_step).
Input: the atlas G-buffer (position m, normal towards the probe with w = side). In and out: the offset
texture, (nx, ny nz) like the state, RGBA32F: xyz the offset (m, world axes), w 1 where this step moved
the probe.
clear_moved: the atlas tiles of the probes the step moved set to 0, before they are captured again.
"""

from __future__ import annotations

import numpy as np

from ..backends.base import Backend, Image, Sampler, ShaderSpec, Var, group_count
from ..probe_grid import (
    RELOCATE_CLEARANCE_RATIO,
    RELOCATE_INSIDE_SHARE,
    RELOCATE_MAX_OFFSET_RATIO,
    RELOCATE_MIN_EXIT_RATIO,
    RELOCATE_MIN_STEP_RATIO,
    ProbeGrid,
)
from .declare import PassDecl
from .probe_capture import ATLAS, ATLAS_NORMAL, ATLAS_POSITION, ATLAS_UNIFORMS, GRID_UNIFORMS, OFFSET, grid_uniforms

DECL = PassDecl("probe_relocate", "setup", (ATLAS_POSITION, ATLAS_NORMAL), (OFFSET, *ATLAS),
                "probes moved out of solids and off near surfaces, then captured again")

SPEC = ShaderSpec(
    name="probe_relocate",
    compute="probes/relocate.comp.glsl",
    local_size=(8, 8, 1),
    samplers=(Sampler("atlas_position", "2D"), Sampler("atlas_normal", "2D")),
    images=(Image("probe_offset", "2D", "RGBA32F", "read_write"),),
    uniforms=(*GRID_UNIFORMS, Var("clearance_m", "float"), Var("max_offset_m", "float"),
              Var("inside_share", "float"), Var("min_exit_m", "float"), Var("min_step_m", "float"),
              Var("bounds_lo_m", "vec3"), Var("bounds_hi_m", "vec3")),
)

CLEAR_SPEC = ShaderSpec(
    name="probe_clear_moved",
    compute="probes/clear_moved.comp.glsl",
    local_size=(8, 8, 1),
    samplers=(Sampler("probe_offset", "2D"),),
    images=tuple(Image(f"atlas_{p.name}", "2D", "RGBA32F", "write") for p in ATLAS),
    uniforms=ATLAS_UNIFORMS,
)


def allocate(backend: Backend, grid: ProbeGrid):
    """The offset texture, all 0: every probe at its grid position."""
    w, h = grid.state_size
    return backend.texture((w, h), data=np.zeros((h, w, 4), np.float32))


def step(backend: Backend, atlas: dict, offset, grid: ProbeGrid, bounds_m) -> tuple[np.ndarray, np.ndarray]:
    """One relocation step of every probe from its capture in `atlas` (bounds_m: the occupied bounds (lo,
    hi) the grid was fitted to); returns the offsets (count, 3) (m) and which probes moved ((count,)
    bool), in probe order."""
    s = grid.spacing_m
    backend.dispatch(backend.program(SPEC), group_count(offset.size, SPEC.local_size),
                     uniforms={**grid_uniforms(SPEC, grid), "clearance_m": RELOCATE_CLEARANCE_RATIO * s,
                               "max_offset_m": RELOCATE_MAX_OFFSET_RATIO * s, "inside_share": RELOCATE_INSIDE_SHARE,
                               "min_exit_m": RELOCATE_MIN_EXIT_RATIO * s, "min_step_m": RELOCATE_MIN_STEP_RATIO * s,
                               "bounds_lo_m": bounds_m[0], "bounds_hi_m": bounds_m[1]},
                     samplers={"atlas_position": atlas["position"], "atlas_normal": atlas["normal"]},
                     images={"probe_offset": offset})
    table = backend.read(offset).reshape(-1, 4)  # (ny nz, nx) rows ravel in probe order
    return table[:, :3].astype(np.float64), table[:, 3] > 0.0


def clear_moved(backend: Backend, atlas: dict, offset, grid: ProbeGrid) -> None:
    """Zero the atlas tiles of the probes the last step moved (offset.w = 1)."""
    backend.dispatch(backend.program(CLEAR_SPEC), group_count(grid.atlas_size, CLEAR_SPEC.local_size),
                     uniforms=grid_uniforms(CLEAR_SPEC, grid), samplers={"probe_offset": offset},
                     images={f"atlas_{p.name}": atlas[p.name] for p in ATLAS})
