"""LPV re-injection pass: the next diffuse bounce, emitted by the voxelized surfaces (docs/LPV.md).

Inputs: the previous bounce's accumulation `acc_r/g/b` (RGBA32F 3D, L1 SH, W/sr per cell by direction
of travel, as lpv_lookup reads it), the voxelizer's `vox_normal` (xyz mean normal, w = surface area in
the cell in cells^2), `vox_albedo` (rgb diffuse albedo) and `vox_projected` (per axis projected area,
cells^2) on the LPV grid. Output: a fresh snapshot
`sh_r/g/b` (RGBA32F 3D, written in every cell, not accumulated). A cell A with geometry reflects
phi = albedo * E * area (W): E the irradiance on a surface at A's centre, on the better lit side m of
+-n, read at A's centre + h m / 2 from the trilinear corners that do not block along m (renormalised;
A's own surface blocks, so A's own light, mostly what its surface emitted the other way, is not read
as arriving: the sun-lit roof of window-room re-emitted its own light into the room); area = w h^2.
Its Lambertian lobe phi / pi * cosine_lobe(m) goes to the neighbours A + d in the shares
max(0, m.d) / |m|_1 (sum 1). Gather form: one compute invocation per
cell reads its 6 neighbours; no atomics. `add` sums one bounce's accumulation into the total.

Emitter classes (docs/LPV.md): `own` runs once per class with that class's light alone and writes the
signed reading on each surface's side of that class into `own_front` / `own_back` (RGBA32F 3D); `run`
with them subtracts it before the clamp, so a surface reflects the light of the other classes only.
"""

from __future__ import annotations

import dataclasses

from ..backends.base import Backend, Image, Sampler, ShaderSpec, Var, group_count
from ..grid import Grid
from .declare import LPV_ACCUMULATED, LPV_SNAPSHOT, VOX_ALBEDO, VOX_NORMAL, VOX_PROJECTED, PassDecl

SPEC = ShaderSpec(
    name="lpv_reinject",
    compute="lpv/reinject.comp.glsl",
    local_size=(4, 4, 4),
    samplers=tuple(Sampler(f"acc_{c}", "3D") for c in "rgb")
    + tuple(Sampler(f"vox_{q}", "3D") for q in ("normal", "albedo", "projected")),
    images=tuple(Image(f"sh_{c}", "3D", "RGBA32F", "write") for c in "rgb"),
    uniforms=(Var("dims", "ivec3"),),
)
OWN_LIGHT = dataclasses.replace(SPEC, name="lpv_reinject_own_light", defines=(("OWN_LIGHT", "1"),),
                                samplers=SPEC.samplers + (Sampler("own_front", "3D"), Sampler("own_back", "3D")))
OWN_PASS = ShaderSpec(
    name="lpv_reinject_own_pass",
    compute="lpv/reinject.comp.glsl",
    local_size=(4, 4, 4),
    samplers=tuple(Sampler(f"acc_{c}", "3D") for c in "rgb") + (Sampler("vox_normal", "3D"),
                                                                 Sampler("vox_projected", "3D")),
    images=(Image("own_front", "3D", "RGBA32F", "write"), Image("own_back", "3D", "RGBA32F", "write")),
    uniforms=(Var("dims", "ivec3"), Var("emitter", "int")),
    defines=(("OWN_PASS", "1"),),
)

ADD = ShaderSpec(
    name="lpv_add",
    compute="lpv/add.comp.glsl",
    local_size=(4, 4, 4),
    samplers=tuple(Sampler(f"bounce_{c}", "3D") for c in "rgb"),
    images=tuple(Image(f"acc_{c}", "3D", "RGBA32F", "read_write") for c in "rgb"),
    uniforms=(Var("dims", "ivec3"),),
)


DECL = PassDecl("lpv_reinject", "gather", (LPV_ACCUMULATED, VOX_NORMAL, VOX_ALBEDO, VOX_PROJECTED),
                (LPV_SNAPSHOT, LPV_ACCUMULATED), "the next bounce re-emitted by the voxelized surfaces")


def run(backend: Backend, acc: dict, voxels: dict, snapshot: dict, grid: Grid, own: dict | None = None) -> None:
    """acc (keys acc_r/g/b) -> snapshot (keys sh_r/g/b), overwritten in every cell; `voxels`: the
    voxelizer's vox_normal, vox_albedo and vox_projected; `own` (keys own_front, own_back, written by
    `own` for every class): each side's own-class reading is subtracted."""
    spec = SPEC if own is None else OWN_LIGHT
    samplers = {**acc, **{k: voxels[k] for k in ("vox_normal", "vox_albedo", "vox_projected")}, **(own or {})}
    backend.dispatch(backend.program(spec), group_count(grid.dims, spec.local_size), uniforms={"dims": grid.dims},
                     samplers=samplers, images=snapshot)


def own(backend: Backend, acc: dict, voxels: dict, out: dict, grid: Grid, emitter: int) -> None:
    """out (keys own_front, own_back) at the surfaces whose side +n / -n is of class `emitter` := the
    signed reading of acc (that class's light alone) there, as `run` reads it before the clamp; other
    cells are left as they are."""
    backend.dispatch(backend.program(OWN_PASS), group_count(grid.dims, OWN_PASS.local_size),
                     uniforms={"dims": grid.dims, "emitter": emitter},
                     samplers={**acc, "vox_normal": voxels["vox_normal"], "vox_projected": voxels["vox_projected"]},
                     images=out)


def add(backend: Backend, bounce: dict, total: dict, grid: Grid) -> None:
    """total (keys acc_r/g/b) += bounce (keys acc_r/g/b), per cell."""
    backend.dispatch(backend.program(ADD), group_count(grid.dims, ADD.local_size), uniforms={"dims": grid.dims},
                     samplers={f"bounce_{c}": bounce[f"acc_{c}"] for c in "rgb"}, images=total)
