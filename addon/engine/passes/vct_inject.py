"""VCT radiance injection: every RSM texel's reflected flux into the six directional flux volumes,
one light at a time.

run (per RSM face): additive point splats of the face's VPLs into a light's scratch atlas: six RGBA32F
2D textures of atlas.size, one per direction ("px" .. "nz") attached to `target` in DIRECTIONS order;
per cell and axis direction t of travel, rgb = the sum over its VPLs of phi * max(0, n.t) (W) and a =
of their surfel areas A * max(0, n.t) / h^2 (RSM footprints, cross-section fractions): one point into
the cell holding the VPL, or filtered (VctConfig.filtered_injection) shared between the 2 x 2 cells
nearest it along its surface (`filtered_cells`, four points per texel), so its flux moves continuously
with the light.
add_light (once per light, after its faces): adds rgb x min(1, 4 x projected area along t / a) to the
flux atlas vct_pyramid.level0 reads: a VPL whose footprint overhangs the sliver of geometry its cell
holds no longer makes that cell hundreds of times brighter than the surface
(gpu_shaders/vct/add_light.comp.glsl). Linear in each light's power, and lights add.

Inputs: one RSM face (position; normal, w = surfel area m^2; flux, W), the VCT Grid, an Atlas; the
voxelizer's vox_projected. Portable scatter (ARCHITECTURE.md section 3): additive point splats into the
layers-as-tiles atlas (passes/atlas.py), one draw per face; the light's addition is a compute pass.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from ..backends.base import Backend, Image, Sampler, ShaderSpec, Var, group_count
from ..grid import Grid
from .atlas import Atlas, splat, splat_spec
from .declare import RSM, VCT_FLUX, VOX_PROJECTED, PassDecl
from .lpv_inject import emitter_class
from .sky_light import SKY_RSM

DIRECTIONS = ("px", "nx", "py", "ny", "pz", "nz")  # travel along +x, -x, +y, -y, +z, -z

SPEC = splat_spec("vct_inject", "vct/inject.vert.glsl", "vct/inject.frag.glsl",
                  varyings=tuple(Var(f"v_{d}", "vec4") for d in DIRECTIONS),
                  outputs=tuple(Var(f"out_{d}", "vec4") for d in DIRECTIONS))
# Filtered: reads the voxelizer's projected areas to keep a VPL's share out of cells without its surface.
SPEC_FILTERED = dataclasses.replace(SPEC, name="vct_inject_filtered", defines=(("FILTERED_INJECTION", "1"),),
                                    samplers=(*SPEC.samplers, Sampler("vox_projected", "3D")))
FILTER_CORNERS = 4  # points per RSM texel when filtered: atlas.texel_points(copies=FILTER_CORNERS)


DECL = PassDecl("vct_inject", "solve", (*RSM, VOX_PROJECTED), (VCT_FLUX,),
                "each face's VPLs splatted per travel direction; each light capped by the geometry")
SKY_DECL = PassDecl("vct_inject_sky", "solve", (*SKY_RSM, VOX_PROJECTED), (VCT_FLUX,),
                    "the sky's RSM tiles' VPLs splatted and capped as one light: the world's bounce")


def spec(filtered: bool) -> ShaderSpec:
    """The injection program (its point mesh, atlas.texel_points with points_per_texel(filtered) copies)."""
    return SPEC_FILTERED if filtered else SPEC


def points_per_texel(filtered: bool) -> int:
    return FILTER_CORNERS if filtered else 1


def filtered_cells(positions: np.ndarray, normals: np.ndarray, projected: np.ndarray, grid: Grid):
    """The filtered injection's twin (gpu_shaders/vct/inject.vert.glsl): per VPL (n, 3) the four cells
    (n, 4, 3) and weights (n, 4). Along the normal's dominant axis a (lpv_inject.emitter_class's tie
    rule) the cell layer holding the VPL; along the two others the bilinear weights of the 2 x 2 cells
    whose centres surround it, each kept only where that cell holds geometry facing a (projected (X, Y,
    Z, 3) in cells^2, > 0) and renormalised; where none does, all of it in the VPL's own cell."""
    g = (np.asarray(positions, np.float64) - grid.origin_m) / grid.cell_size_m
    axis = emitter_class(np.asarray(normals)) // 2
    n = len(g)
    others = np.array([[1, 2], [0, 2], [0, 1]])[axis]  # (n, 2)
    across = np.take_along_axis(g, others, axis=1) - 0.5
    base = np.floor(across).astype(int)
    frac = across - base
    layer = np.floor(g[np.arange(n), axis]).astype(int)
    corners = np.array([[0, 0], [1, 0], [0, 1], [1, 1]])  # corner k = (k & 1, k >> 1), as the shader
    cells = np.zeros((n, 4, 3), int)
    weights = np.zeros((n, 4))
    dims = np.array(grid.dims)
    for k, (i, j) in enumerate(corners):
        c = np.zeros((n, 3), int)
        c[np.arange(n), axis] = layer
        c[np.arange(n), others[:, 0]] = base[:, 0] + i
        c[np.arange(n), others[:, 1]] = base[:, 1] + j
        inside = np.all((c >= 0) & (c < dims), axis=1)
        cc = np.clip(c, 0, dims - 1)
        facing = np.where(inside, projected[cc[:, 0], cc[:, 1], cc[:, 2], axis], 0.0) > 0.0
        w = np.where(i, frac[:, 0], 1 - frac[:, 0]) * np.where(j, frac[:, 1], 1 - frac[:, 1])
        cells[:, k], weights[:, k] = c, np.where(facing, w, 0.0)
    total = weights.sum(axis=1, keepdims=True)
    none = total[:, 0] <= 0.0
    weights = np.where(total > 0.0, weights / np.where(total > 0.0, total, 1.0), 0.0)
    cells[none, 0], weights[none, 0] = np.floor(g[none]).astype(int), 1.0
    return cells, weights

ADD_LIGHT = ShaderSpec(
    name="vct_add_light",
    compute="vct/add_light.comp.glsl",
    local_size=(4, 4, 4),
    samplers=(*(Sampler(f"light_{d}", "2D") for d in DIRECTIONS), Sampler("vox_projected", "3D")),
    images=tuple(Image(f"flux_{d}", "2D", "RGBA32F", "read_write") for d in DIRECTIONS),
    uniforms=(Var("dims", "ivec3"), Var("tiles_x", "int")),
)


def run(backend: Backend, target, points, rsm: dict, grid: Grid, atlas: Atlas, vox_projected=None) -> None:
    """Add one RSM face's VPLs into the light's scratch atlas behind `target` (six textures): filtered
    when given the voxelizer's vox_projected, else one point per VPL; `points` made for spec(filtered)."""
    filtered = vox_projected is not None
    splat(backend, spec(filtered), target, points, rsm, grid, atlas,
          {"vox_projected": vox_projected} if filtered else None)


def add_light(backend: Backend, light: dict, flux: dict, vox_projected, grid: Grid, atlas: Atlas) -> None:
    """flux[d] += the light's scratch light[d], capped where footprints overhang the geometry (module doc)."""
    backend.dispatch(backend.program(ADD_LIGHT), group_count(grid.dims, ADD_LIGHT.local_size),
                     uniforms={"dims": grid.dims, "tiles_x": atlas.tiles_x},
                     samplers={**{f"light_{d}": light[d] for d in DIRECTIONS}, "vox_projected": vox_projected},
                     images={f"flux_{d}": flux[d] for d in DIRECTIONS})
