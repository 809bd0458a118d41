"""LPV propagation pass: one gather step per dispatch, ping-pong volumes, snapshots accumulated.

Inputs: the source snapshot `src_r/g/b` (RGBA32F 3D, L1 SH of radiant intensity in W/sr by direction
of travel, per colour), optionally a geometry volume: `block_plus` / `block_minus` (per axis, the share
of a cell's blocking on light leaving it along +axis / -axis), which `blocking` computes once per
voxelization from the voxelizer's `vox_projected` (per axis the area the surfaces project along it,
cells^2) and, with surface offsets, `vox_offset` (per axis the surfaces' mean offset from the cell's
centre, cells: which side's transfers the blocking falls on). Outputs: the next snapshot `dst_r/g/b`
and the accumulation `acc_r/g/b` (read-write). On the first step acc = source_weight * src +
step_weight * dst; afterwards acc += step_weight * dst.

Variants (gpu_shaders/lpv/propagate.comp.glsl has the equations; docs/LPV.md the derivations):
- classic: CLPV 5-face transfer, face solid angles 0.4006696846 / 0.4234313544 sr, re-emission as a
  clamped-cosine lobe along the face normal. Flux-conserving (signed SH), but it turns most of the
  light sideways.
- improved: B receives M_d c_A, the L1 projection of I_A(w) max(0, w.d) / |w|_1 (sum_d M_d = 1:
  flux-conserving, light keeps its direction), the injection snapshot is not accumulated (no light in
  the emitter's own cell), and each snapshot is weighted by PATH_WEIGHT = the mean path length per
  cell visit (cells), so the accumulated sum is fluence x h^2 rather than visits.
The six directions are unrolled; classic loops over 6 faces in each: far below llvmpipe's 65,535 cap.
"""

from __future__ import annotations

import functools

import numpy as np

from .. import sh
from ..backends.base import Backend, Image, Sampler, ShaderSpec, Var, group_count
from ..grid import Grid
from .declare import LPV_ACCUMULATED, LPV_BLOCKING, LPV_SNAPSHOT, VOX_OFFSET, VOX_PROJECTED, PassDecl

_UNIFORMS = (Var("dims", "ivec3"), Var("first_step", "int"), Var("source_weight", "float"),
             Var("step_weight", "float"), Var("m_cross", "float"), Var("m_along", "float"),
             Var("m_side", "float"))
_IMAGES = tuple(Image(f"dst_{c}", "3D", "RGBA32F", "write") for c in "rgb") + tuple(
    Image(f"acc_{c}", "3D", "RGBA32F", "read_write") for c in "rgb")
_SRC = tuple(Sampler(f"src_{c}", "3D") for c in "rgb")


DECL = PassDecl("lpv_propagate", "solve", (LPV_SNAPSHOT, LPV_BLOCKING), (LPV_SNAPSHOT, LPV_ACCUMULATED),
                "propagation steps, accumulated (with emitter classes the gather runs them per class)")
BLOCKING_DECL = PassDecl("lpv_blocking", "setup", (VOX_PROJECTED, VOX_OFFSET), (LPV_BLOCKING,),
                         "the geometry volume's blocking per axis, once per voxelization")


def _spec(variant: str, geometry_volume: bool) -> ShaderSpec:
    defines = (("IMPROVED", "1"),) if variant == "improved" else ()
    samplers = _SRC
    if geometry_volume:
        defines += (("GEOMETRY_VOLUME", "1"),)
        samplers += (Sampler("block_plus", "3D"), Sampler("block_minus", "3D"))
    return ShaderSpec(name=f"lpv_propagate_{variant}{'_gv' if geometry_volume else ''}",
                      compute="lpv/propagate.comp.glsl", local_size=(4, 4, 4), samplers=samplers,
                      images=_IMAGES, uniforms=_UNIFORMS, defines=defines)


SPECS = {(v, gv): _spec(v, gv) for v in ("classic", "improved") for gv in (False, True)}


def _blocking_spec(surface_offsets: bool) -> ShaderSpec:
    return ShaderSpec(
        name="lpv_blocking" + ("_offsets" if surface_offsets else ""), compute="lpv/blocking.comp.glsl",
        local_size=(4, 4, 4),
        samplers=(Sampler("vox_projected", "3D"),) + ((Sampler("vox_offset", "3D"),) if surface_offsets else ()),
        images=(Image("block_plus", "3D", "RGBA32F", "write"), Image("block_minus", "3D", "RGBA32F", "write")),
        uniforms=(Var("dims", "ivec3"),), defines=(("SURFACE_OFFSETS", "1"),) if surface_offsets else ())


BLOCKING = {so: _blocking_spec(so) for so in (False, True)}


def blocking(backend: Backend, voxels: dict, grid: Grid, surface_offsets: bool, out: dict | None = None) -> dict:
    """The geometry volume a propagation reads (block_plus, block_minus; `out`'s textures, or new ones)
    from the voxels (vox_projected, and vox_offset with surface_offsets)."""
    out = out or {k: backend.texture(grid.dims) for k in ("block_plus", "block_minus")}
    spec = BLOCKING[surface_offsets]
    samplers = {"vox_projected": voxels["vox_projected"]}
    if surface_offsets:
        samplers["vox_offset"] = voxels["vox_offset"]
    backend.dispatch(backend.program(spec), group_count(grid.dims, spec.local_size), uniforms={"dims": grid.dims},
                     samplers=samplers, images=out)
    return out


@functools.cache
def improved_constants(n_theta: int = 1024) -> dict[str, float]:
    """The symmetric entries of M_+x = integral Y_i Y_j max(0, w_x) / |w|_1 dw, and PATH_WEIGHT =
    integral Y_i Y_i / |w|_1 dw (the same for all four coefficients by symmetry: mean of 1 / |w|_1 over
    the sphere, 0.674). Midpoint quadrature, ~1e-6."""
    dirs, weights = sh.sphere_quadrature(n_theta, 2 * n_theta)
    inv_l1 = 1.0 / np.abs(dirs).sum(axis=1)
    wx = np.maximum(dirs[:, 0], 0.0) * inv_l1 * weights
    return {
        "m_cross": float(np.sum(wx * sh.Y00 * sh.Y1 * dirs[:, 0])),
        "m_along": float(np.sum(wx * sh.Y1**2 * dirs[:, 0] ** 2)),
        "m_side": float(np.sum(wx * sh.Y1**2 * dirs[:, 1] ** 2)),
        "path_weight": float(np.sum(weights * inv_l1) / (4.0 * np.pi)),
    }


def weights(variant: str) -> tuple[float, float]:
    """(source_weight, step_weight): how the injected snapshot and each propagated one are accumulated."""
    if variant == "improved":
        return 0.0, improved_constants()["path_weight"]
    return 1.0, 1.0


def run(backend: Backend, src: dict, dst: dict, acc: dict, grid: Grid, variant: str, first_step: bool,
        geometry: dict | None = None, step_scale: float = 1.0) -> None:
    """One step: src (sh_r/g/b textures) -> dst, accumulated into acc (keys acc_r/g/b) with `weights`'
    step weight times `step_scale` (the far field's share of the step, lpv_far_field); `geometry`:
    `blocking`'s output when a geometry volume blocks the transfers."""
    spec = SPECS[(variant, geometry is not None)]
    c = improved_constants() if variant == "improved" else {"m_cross": 0.0, "m_along": 0.0, "m_side": 0.0}
    source_weight, step_weight = weights(variant)
    samplers = {f"src_{ch}": src[f"sh_{ch}"] for ch in "rgb"}
    if geometry is not None:
        samplers.update(geometry)
    images = {**{f"dst_{ch}": dst[f"sh_{ch}"] for ch in "rgb"}, **{f"acc_{ch}": acc[f"acc_{ch}"] for ch in "rgb"}}
    uniforms = {"dims": grid.dims, "first_step": int(first_step), "source_weight": source_weight,
                "step_weight": step_weight * step_scale, "m_cross": c["m_cross"], "m_along": c["m_along"],
                "m_side": c["m_side"]}
    backend.dispatch(backend.program(spec), group_count(grid.dims, spec.local_size), uniforms=uniforms,
                     samplers=samplers, images=images)
