"""Diffusion propagation: one gather step per dispatch, ping-pong snapshots, absorbed flux accumulated.

Inputs: the snapshot `src_r/g/b` (RGBA32F 3D, L1 SH of radiant intensity W/sr by direction of travel),
the cells (diffusion_cells). Outputs: the next snapshot `dst_r/g/b` and `acc_plus` / `acc_minus`
(RGBA32F 3D, rgb = flux in W absorbed on each side of a cell's plane; first_step: written, else added).
gpu_shaders/diffusion/propagate.comp.glsl has the step (Mavridis et al., seeds 000, the face transfer
normalised by 3 / (2 pi)); diffusion_reference.step is its twin and docs/DIFFUSION.md derives it.
`add` sums one bounce's absorbed flux into the light field's total.
"""

from __future__ import annotations

from ..backends.base import Backend, Image, Sampler, ShaderSpec, Var, group_count
from ..grid import Grid
from .declare import PassDecl, Port
from .diffusion_cells import CELL_BLOCK, CELL_NORMAL
from .diffusion_inject import SNAPSHOT

ABSORBED = Port("diffusion", "absorbed", "RGBA32F", "grid", "one bounce's flux (W) absorbed on each side of a plane")
ACCUMULATED = Port("diffusion", "accumulated", "RGBA32F", "grid",
                   "every bounce's flux (W) absorbed on each side of a plane: the light field")

SPEC = ShaderSpec(
    name="diffusion_propagate",
    compute="diffusion/propagate.comp.glsl",
    local_size=(4, 4, 4),
    samplers=(*(Sampler(f"src_{c}", "3D") for c in "rgb"), Sampler("cell_normal", "3D"), Sampler("cell_block", "3D")),
    images=(*(Image(f"dst_{c}", "3D", "RGBA32F", "write") for c in "rgb"),
            Image("acc_plus", "3D", "RGBA32F", "read_write"), Image("acc_minus", "3D", "RGBA32F", "read_write")),
    uniforms=(Var("dims", "ivec3"), Var("first_step", "int")),
)

ADD = ShaderSpec(
    name="diffusion_add",
    compute="diffusion/add.comp.glsl",
    local_size=(4, 4, 4),
    samplers=(Sampler("bounce_plus", "3D"), Sampler("bounce_minus", "3D")),
    images=(Image("total_plus", "3D", "RGBA32F", "read_write"), Image("total_minus", "3D", "RGBA32F", "read_write")),
    uniforms=(Var("dims", "ivec3"), Var("first", "int")),
)

DECL = PassDecl("diffusion_propagate", "solve", (SNAPSHOT, CELL_NORMAL, CELL_BLOCK), (SNAPSHOT, ABSORBED, ACCUMULATED),
                "propagation steps, each bounce's absorbed flux summed into the total")


def sides(backend: Backend, grid: Grid) -> dict:
    """A pair of per-side flux volumes, keyed flux_plus / flux_minus."""
    return {k: backend.texture(grid.dims) for k in ("flux_plus", "flux_minus")}


def run(backend: Backend, src: dict, dst: dict, absorbed: dict, cells: dict, grid: Grid, first_step: bool) -> None:
    """One step: src (sh_r/g/b) -> dst, the flux absorbed written (first_step) or added into `absorbed`
    (flux_plus / flux_minus)."""
    backend.dispatch(backend.program(SPEC), group_count(grid.dims, SPEC.local_size),
                     uniforms={"dims": grid.dims, "first_step": int(first_step)},
                     samplers={**{f"src_{c}": src[f"sh_{c}"] for c in "rgb"}, **cells},
                     images={**{f"dst_{c}": dst[f"sh_{c}"] for c in "rgb"}, "acc_plus": absorbed["flux_plus"],
                             "acc_minus": absorbed["flux_minus"]})


def add(backend: Backend, bounce: dict, total: dict, grid: Grid, first: bool) -> None:
    """total := bounce (first) or total + bounce, per side."""
    backend.dispatch(backend.program(ADD), group_count(grid.dims, ADD.local_size),
                     uniforms={"dims": grid.dims, "first": int(first)},
                     samplers={"bounce_plus": bounce["flux_plus"], "bounce_minus": bounce["flux_minus"]},
                     images={"total_plus": total["flux_plus"], "total_minus": total["flux_minus"]})
