"""RSM reduction: one VPL per factor x factor block of an RSM face, for injections whose grid cannot
hold more (LPV: a 32^3 grid gains nothing from 65k VPLs per face; its injection was the largest pass
of an LPV update on an H100, 0.8 of 1.65 ms).

Inputs: one RSM face (position, w = valid; normal, w = surfel area m^2; flux W). Output: the same three
textures at resolution / factor: flux and area summed exactly, position and normal flux-weighted means
(gpu_shaders/rsm/reduce.comp.glsl).
"""

from __future__ import annotations

from ..backends.base import Backend, Image, Sampler, ShaderSpec, Var, group_count
from .declare import RSM, PassDecl

SPEC = ShaderSpec(
    name="rsm_reduce",
    compute="rsm/reduce.comp.glsl",
    local_size=(8, 8, 1),
    samplers=(Sampler("rsm_position", "2D"), Sampler("rsm_normal", "2D"), Sampler("rsm_flux", "2D")),
    images=(Image("out_position", "2D"), Image("out_normal", "2D"), Image("out_flux", "2D")),
    uniforms=(Var("factor", "int"),),
)


DECL = PassDecl("rsm_reduce", "solve", RSM, RSM, "one VPL per block of an RSM face, for a coarse injection")


def factor_for(rsm_resolution: int, grid_cells: int, vpls_per_cell: int = 2) -> int:
    """The largest power of two that leaves at least `vpls_per_cell` VPLs per grid cell along a side
    of the RSM (a face seen whole covers at most ~grid_cells cells across), and divides the RSM."""
    factor = 1
    while rsm_resolution % (2 * factor) == 0 and rsm_resolution // (2 * factor) >= vpls_per_cell * grid_cells:
        factor *= 2
    return factor


def textures(backend: Backend, rsm_resolution: int, factor: int) -> dict:
    size = (rsm_resolution // factor, rsm_resolution // factor)
    return {k: backend.texture(size) for k in ("position", "normal", "flux")}


def run(backend: Backend, rsm: dict, out: dict, factor: int) -> None:
    backend.dispatch(backend.program(SPEC), group_count(out["flux"].size, SPEC.local_size),
                     uniforms={"factor": factor},
                     samplers={f"rsm_{k}": rsm[k] for k in ("position", "normal", "flux")},
                     images={f"out_{k}": out[k] for k in ("position", "normal", "flux")})
