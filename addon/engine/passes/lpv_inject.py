"""LPV injection pass: every RSM texel is a VPL added to the SH volumes (Kaplanyan 2009; seeds 002).

Inputs: one RSM face (position; normal, w = surfel area; flux, W), the LPV Grid. Outputs (accumulated,
never cleared here): `lpv.sh_r`, `lpv.sh_g`, `lpv.sh_b`, RGBA32F 3D textures of grid.dims holding, per
colour channel, the L1 SH (order 1, y, z, x) of the radiant intensity in W/sr that leaves the cell, by
direction of travel. A VPL of flux phi and normal n adds phi / pi * (0.886227, 1.023327 n) (its
Lambertian intensity phi / pi * max(0, n.w) projected) to the cell containing pos + 0.5 cell * n; the
cell's flux is the integral of the intensity, 2 sqrt(pi) * c0 (docs/LPV.md derives the units).

Portable scatter (ARCHITECTURE.md section 3): additive point splats into each z-layer of the three
volumes (one framebuffer per layer); each layer's draw culls the points of other layers in the vertex
shader. No atomics.
"""

from __future__ import annotations

import numpy as np

from ..backends.base import Backend, Sampler, ShaderSpec, Var
from ..grid import Grid

SPEC = ShaderSpec(
    name="lpv_inject",
    vertex="lpv/inject.vert.glsl",
    fragment="lpv/inject.frag.glsl",
    samplers=(Sampler("rsm_position", "2D"), Sampler("rsm_normal", "2D"), Sampler("rsm_flux", "2D")),
    uniforms=(Var("grid_origin", "vec3"), Var("cell_size", "float"), Var("dims", "ivec3"), Var("layer", "int")),
    attributes=(Var("texel", "vec2"),),
    varyings=(Var("v_r", "vec4"), Var("v_g", "vec4"), Var("v_b", "vec4")),
    outputs=(Var("out_r", "vec4"), Var("out_g", "vec4"), Var("out_b", "vec4")),
)


def texel_points(backend: Backend, resolution: int, spec: ShaderSpec = SPEC):
    """The point mesh: one vertex per RSM texel (its integer coordinates, attribute `texel`), made once
    per RSM size for the splatting program `spec` (LPV's or VCT's injection)."""
    j, i = np.mgrid[0:resolution, 0:resolution]
    texels = np.stack([i.ravel(), j.ravel()], axis=1).astype(np.float32)
    return backend.mesh(backend.program(spec), {"texel": texels}, "points")


def layer_targets(backend: Backend, volumes: dict, grid: Grid) -> list:
    """One framebuffer per z-layer with the three SH volumes' layers attached (made once per grid)."""
    return [backend.target([(volumes["sh_r"], k), (volumes["sh_g"], k), (volumes["sh_b"], k)])
            for k in range(grid.dims[2])]


def run(backend: Backend, targets: list, points, rsm: dict, grid: Grid) -> None:
    """Add one RSM face's VPLs to the volumes behind `targets` (cleared by the caller per update)."""
    prog = backend.program(SPEC)
    samplers = {"rsm_position": rsm["position"], "rsm_normal": rsm["normal"], "rsm_flux": rsm["flux"]}
    uniforms = {"grid_origin": grid.origin_m, "cell_size": grid.cell_size_m, "dims": grid.dims}
    for k, target in enumerate(targets):
        backend.draw(prog, target, points, uniforms={**uniforms, "layer": k}, samplers=samplers, blend="add")
