"""Diffusion propagation: one gather step per dispatch, ping-pong snapshots, absorbed flux accumulated.

Inputs: the snapshot `src_r/g/b` (RGBA32F 3D, L1 SH of radiant intensity W/sr by direction of travel),
the cells (diffusion_cells). Outputs: the next snapshot `dst_r/g/b` and `acc_plus` / `acc_minus`
(RGBA32F 3D, rgb = flux in W absorbed on each side of a cell's plane; first_step: written, else added).
gpu_shaders/diffusion/propagate.comp.glsl has the step (Mavridis et al., seeds 000): the paper's face
transfer normalised by 3 / (2 pi) (`cone`), or LPV's improved transfer (`directional`, light keeps its
direction); diffusion_reference.step is its twin and docs/DIFFUSION.md derives and measures both.
`add` sums one bounce's absorbed flux into the light field's total (with `skip_class`, one emitter
class's propagation, into every side but those of that class).
"""

from __future__ import annotations

import functools

import numpy as np

from .. import sh
from ..backends.base import Backend, Image, Sampler, ShaderSpec, Var, group_count
from ..grid import Grid
from .declare import PassDecl, Port
from .diffusion_cells import CELL_BLOCK, CELL_NORMAL
from .diffusion_cone_defines import cone_defines
from .diffusion_inject import EVERY_CLASS, SNAPSHOT
from .lpv_propagate import improved_constants

ABSORBED = Port("diffusion", "absorbed", "RGBA32F", "grid", "one bounce's flux (W) absorbed on each side of a plane")
ACCUMULATED = Port("diffusion", "accumulated", "RGBA32F", "grid",
                   "every bounce's flux (W) absorbed on each side of a plane: the light field")

@functools.cache
def spec(transfer: str, faces: bool, cone: int | None = None) -> ShaderSpec:
    """The step's program: `transfer`'s, or with a `cone` (0..5) that cone field's (cone_fields.py),
    whose matrices are compiled in; `faces`: absorbed flux kept by face (the far field's grid)."""
    directional = transfer == "directional" and cone is None
    accumulators = (tuple(Image(f"acc_{i}", "3D", "RGBA32F", "read_write") for i in range(FACE_TEXELS)) if faces
                    else (Image("acc_plus", "3D", "RGBA32F", "read_write"),
                          Image("acc_minus", "3D", "RGBA32F", "read_write")))
    name = f"diffusion_propagate_{transfer}" if cone is None else f"diffusion_propagate_cone_field_{cone}"
    return ShaderSpec(
        name=name + ("_faces" if faces else ""),
        compute="diffusion/propagate.comp.glsl",
        local_size=(4, 4, 4),
        samplers=(*(Sampler(f"src_{c}", "3D") for c in "rgb"), *(() if faces else (Sampler("cell_normal", "3D"),)),
                  Sampler("cell_block", "3D")),
        images=(*(Image(f"dst_{c}", "3D", "RGBA32F", "write") for c in "rgb"), *accumulators),
        uniforms=(Var("dims", "ivec3"), Var("first_step", "int"))
        + ((Var("m_cross", "float"), Var("m_along", "float"), Var("m_side", "float"), Var("flux_cross", "float"))
           if directional else ()),
        defines=(("DIRECTIONAL", "1"),) * directional + (("FACES", "1"),) * faces
        + (cone_defines(cone) if cone is not None else ()),
    )


# The flux per face of a cell, 6 faces x rgb, packed into this many RGBA volumes (diffusion/faces.glsl).
FACE_TEXELS = 5

ADD = ShaderSpec(
    name="diffusion_add",
    compute="diffusion/add.comp.glsl",
    local_size=(4, 4, 4),
    samplers=(Sampler("bounce_plus", "3D"), Sampler("bounce_minus", "3D"), Sampler("cell_normal", "3D")),
    images=(Image("total_plus", "3D", "RGBA32F", "read_write"), Image("total_minus", "3D", "RGBA32F", "read_write")),
    uniforms=(Var("dims", "ivec3"), Var("first", "int"), Var("skip_class", "int")),
)

DECL = PassDecl("diffusion_propagate", "solve", (SNAPSHOT, CELL_NORMAL, CELL_BLOCK), (SNAPSHOT, ABSORBED, ACCUMULATED),
                "propagation steps, each bounce's absorbed flux summed into the total")


@functools.cache
def flux_cross() -> float:
    """The `directional` transfer's weight of a field's band-1 coefficient along a face's axis in the flux
    through that face, raw = 2 sqrt(pi) (c0 / 6 +- flux_cross c_axis) (LPV's M_d has m_cross there).

    The L1 field of a Lambertian lobe is broader than the lobe: with m_cross an upward lobe in an open
    cell sends 0.370 of its flux up and 0.158 through each side, where its directions w, each through
    face d by max(0, w.d) / |w|_1 (the partition M_d projects), send 0.449 up and 0.138 sideways
    (tools/diffusion_box.py). The light then spreads sideways at every step: above a lit floor patch
    the walls took what the ceiling should have. This weight makes the partition exact for a Lambertian
    lobe, as it is for an isotropic field (c_axis = 0: unchanged). Only the flux's row of M_d changes,
    so sum_d M_d is still 1 (its +-d entries cancel) and the faces still carry the field itself.
    With the lobe's coefficients a = c0 / 6 and b = m_cross c_up, its down face clamped (a < b) and the
    faces scaled to its flux, the up share is (a + k b) / (5 a + k b); equal to the exact share s when
    k = a (5 s - 1) / (b (1 - s)) (1.680): flux_cross = k m_cross."""
    dirs, weights = sh.sphere_quadrature(1024, 2048)
    up = np.maximum(dirs[:, 2], 0.0)
    exact_up_share = float(np.sum(weights * up / np.pi * dirs[:, 2] / np.abs(dirs).sum(axis=1)))
    m_cross = improved_constants()["m_cross"]
    lobe = sh.cosine_lobe_l1(np.array([0.0, 0.0, 1.0]))
    a, b = lobe[0] / 6.0, m_cross * lobe[2]
    k = a * (5.0 * exact_up_share - 1.0) / (b * (1.0 - exact_up_share))
    return float(k * m_cross)


def sides(backend: Backend, grid: Grid) -> dict:
    """A pair of per-side flux volumes, keyed flux_plus / flux_minus."""
    return {k: backend.texture(grid.dims) for k in ("flux_plus", "flux_minus")}


def faces(backend: Backend, grid: Grid) -> dict:
    """Volumes of flux per face of a cell (acc_0 .. acc_4, diffusion/faces.glsl's packing)."""
    return {f"acc_{i}": backend.texture(grid.dims) for i in range(FACE_TEXELS)}


def run(backend: Backend, src: dict, dst: dict, absorbed: dict, cells: dict, grid: Grid, first_step: bool,
        transfer: str = "cone", cone: int | None = None) -> None:
    """One step: src (sh_r/g/b) -> dst, the flux absorbed written (first_step) or added into `absorbed`:
    per side (flux_plus / flux_minus, from `sides`) or per face it came through (acc_0 .. acc_4, from
    `faces`: the far field's grid). cone: the fields are that cone field's (cone_fields.py; `transfer`
    is then unused)."""
    by_face = "acc_0" in absorbed
    spec_ = spec(transfer, by_face, cone)
    uniforms = {"dims": grid.dims, "first_step": int(first_step)}
    if transfer == "directional" and cone is None:
        c = improved_constants()
        uniforms.update(m_cross=c["m_cross"], m_along=c["m_along"], m_side=c["m_side"], flux_cross=flux_cross())
    images = (dict(absorbed) if by_face
              else {"acc_plus": absorbed["flux_plus"], "acc_minus": absorbed["flux_minus"]})
    backend.dispatch(backend.program(spec_), group_count(grid.dims, spec_.local_size), uniforms=uniforms,
                     samplers={**{f"src_{c}": src[f"sh_{c}"] for c in "rgb"}, **cells},
                     images={**{f"dst_{c}": dst[f"sh_{c}"] for c in "rgb"}, **images})


def add(backend: Backend, bounce: dict, total: dict, grid: Grid, first: bool, cell_normal,
        skip_class: int = EVERY_CLASS) -> None:
    """total := bounce (first) or total + bounce, per side; the sides of `skip_class` (their normal's
    dominant signed axis in `cell_normal`, diffusion_inject.EMITTER_CLASSES) keep their total (first:
    0), unless it is EVERY_CLASS."""
    backend.dispatch(backend.program(ADD), group_count(grid.dims, ADD.local_size),
                     uniforms={"dims": grid.dims, "first": int(first), "skip_class": skip_class},
                     samplers={"bounce_plus": bounce["flux_plus"], "bounce_minus": bounce["flux_minus"],
                               "cell_normal": cell_normal},
                     images={"total_plus": total["flux_plus"], "total_minus": total["flux_minus"]})
