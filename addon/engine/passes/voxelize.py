"""Voxelization pass (shared by VCT, LPV's geometry volume and voxel visibility).

Inputs: scene triangles; a Grid. Outputs (RGBA32F 3D textures of grid.dims, canonical x, y, z layout):
`vox_albedo` (diffuse albedo, a = occupancy 0/1), `vox_normal` (area-weighted mean normal, w = surface
area in the cell in cell units^2), `vox_emission` (emitted radiance W/m^2/sr, a = occupancy),
`vox_projected` (xyz = per axis the larger of the areas the surfaces facing + and - project along it,
in cell units^2: a one-sided wall its area, both faces of a thin wall one of them, a closed column its
silhouette; unlike the mean normal it does not cancel in thin walls: VCT's directional opacity;
w = surface area).

Portable scatter (ARCHITECTURE.md section 3): each triangle is drawn along its dominant axis into the
layers of that axis's volumes with additive blending (conservative coverage, see voxelize.vert.glsl),
one draw per slab; a compute pass merges the three axis volumes and divides out the weights.
Mavridis et al. slice the same way; the thesis in seeds/ (003) used a geometry shader instead.
"""

from __future__ import annotations

import numpy as np

from ..backends.base import Backend, Image, Sampler, ShaderSpec, Var, group_count
from ..grid import Grid
from ..scene import Scene

_UNIFORMS = (Var("grid_origin", "vec3"), Var("cell_size", "float"), Var("dims", "ivec3"), Var("axis", "int"),
             Var("layer", "int"))

RASTER = ShaderSpec(
    name="voxelize",
    vertex="voxelize/voxelize.vert.glsl",
    fragment="voxelize/voxelize.frag.glsl",
    uniforms=_UNIFORMS,
    attributes=(Var("pos_ws", "vec3"), Var("next_ws", "vec3"), Var("prev_ws", "vec3"), Var("tri_normal", "vec3"),
                Var("albedo", "vec3"), Var("emission", "vec3")),
    varyings=(Var("v_uvw", "vec3"), Var("v_plane", "vec4"), Var("v_bbox", "vec4"), Var("v_wrange", "vec3"),
              Var("v_albedo", "vec3"), Var("v_emission", "vec3"), Var("v_normal", "vec3")),
    outputs=(Var("out_albedo", "vec4"), Var("out_normal", "vec4"), Var("out_emission", "vec4"),
             Var("out_projected", "vec4")),
)

_QUANTITIES = ("albedo", "normal", "emission", "projected")

MERGE = ShaderSpec(
    name="voxelize_merge",
    compute="voxelize/merge.comp.glsl",
    local_size=(4, 4, 4),
    samplers=tuple(Sampler(f"{q}_{a}", "3D") for q in _QUANTITIES for a in "xyz"),
    images=tuple(Image(f"vox_{q}", "3D") for q in _QUANTITIES),
    uniforms=(Var("dims", "ivec3"),),
)

# Axis a's volume stores (u, v, w) = the grid coordinates permuted so w runs along a (its layers).
_PERMUTATION = ((1, 2, 0), (2, 0, 1), (0, 1, 2))


def triangle_normals(positions: np.ndarray) -> np.ndarray:
    """Unit geometric normals (n, 3) from the winding; zero for degenerate triangles."""
    n = np.cross(positions[:, 1] - positions[:, 0], positions[:, 2] - positions[:, 0])
    length = np.linalg.norm(n, axis=1, keepdims=True)
    return np.where(length > 0, n / np.maximum(length, 1e-30), 0.0)


def dominant_axis(normals: np.ndarray) -> np.ndarray:
    return np.argmax(np.abs(normals), axis=1)


def slab_triangles(positions_m: np.ndarray, grid: Grid, axis: int) -> dict[int, np.ndarray]:
    """Layer -> indices of the triangles (n, 3, 3) that may write into slab [layer, layer + 1) along
    `axis`: their extent along it in cells, widened by one cell each side (the fragment shader widens a
    triangle's depth by at most 0.5 (|n_u| + |n_v|) / |n_w| <= 1 cell for its dominant axis), clamped
    to the grid. Every triangle appears in each slab it can reach, so nothing is lost."""
    w = (positions_m[:, :, axis] - grid.origin_m[axis]) / grid.cell_size_m
    lo = np.clip(np.floor(w.min(axis=1) - 1.0), 0, grid.dims[axis] - 1).astype(np.int64)
    hi = np.clip(np.floor(w.max(axis=1) + 1.0), 0, grid.dims[axis] - 1).astype(np.int64)
    counts = hi - lo + 1
    tri = np.repeat(np.arange(len(w)), counts)
    layer = np.repeat(lo, counts) + (np.arange(counts.sum()) - np.repeat(np.cumsum(counts) - counts, counts))
    order = np.argsort(layer, kind="stable")
    tri, layer = tri[order], layer[order]
    starts = np.flatnonzero(np.r_[True, layer[1:] != layer[:-1]])
    return {int(layer[b]): tri[b:e] for b, e in zip(starts, np.r_[starts[1:], len(layer)], strict=True)}


class Voxelizer:
    """Allocates the axis and canonical volumes for a grid and voxelizes a scene into them."""

    def __init__(self, backend: Backend, grid: Grid):
        self.backend, self.grid = backend, grid
        be = backend
        self.volumes = {f"vox_{q}": be.texture(grid.dims) for q in _QUANTITIES}
        self._axis_volumes = []
        self._layer_targets = []
        for axis in range(3):
            size = tuple(grid.dims[i] for i in _PERMUTATION[axis])
            vols = {q: be.texture(size) for q in _QUANTITIES}
            self._axis_volumes.append(vols)
            self._layer_targets.append([be.target([(vols[q], k) for q in _QUANTITIES]) for k in range(size[2])])
        self._meshes: list[dict] = [{}, {}, {}]

    def set_scene(self, scene: Scene) -> None:
        """Upload each triangle to its dominant axis, once per slab it can touch: three vertices carrying
        their neighbours. A draw per slab then rasterizes only the triangles near it (drawing every
        triangle into every slab cost Sponza's 67k triangles x 3 x 128 slabs: 60 ms on an H100)."""
        be = self.backend
        prog = be.program(RASTER)
        pos = scene.positions_m.astype(np.float64)
        normals = triangle_normals(pos)
        axes = dominant_axis(normals)
        self._meshes = [{}, {}, {}]
        for axis in range(3):
            sel = np.flatnonzero((axes == axis) & np.any(normals != 0, axis=1))
            if sel.size == 0:
                continue
            for layer, tris in slab_triangles(pos[sel], self.grid, axis).items():
                t = sel[tris]
                p = pos[t]
                attrs = {
                    "pos_ws": p,
                    "next_ws": p[:, [1, 2, 0]],
                    "prev_ws": p[:, [2, 0, 1]],
                    "tri_normal": np.repeat(normals[t][:, None], 3, axis=1),
                    "albedo": np.repeat(scene.albedo[t][:, None], 3, axis=1),
                    "emission": np.repeat(scene.emission[t][:, None], 3, axis=1),
                }
                self._meshes[axis][layer] = be.mesh(prog, {k: v.reshape(-1, 3) for k, v in attrs.items()},
                                                    "triangles")

    def run(self) -> dict:
        be, grid = self.backend, self.grid
        prog = be.program(RASTER)
        uniforms = {"grid_origin": grid.origin_m, "cell_size": grid.cell_size_m, "dims": grid.dims}
        for axis in range(3):
            for k, target in enumerate(self._layer_targets[axis]):
                be.clear(target)
                mesh = self._meshes[axis].get(k)
                if mesh is not None:
                    be.draw(prog, target, mesh, uniforms={**uniforms, "axis": axis, "layer": k}, blend="add")
        samplers = {f"{q}_{'xyz'[a]}": self._axis_volumes[a][q] for q in _QUANTITIES for a in range(3)}
        be.dispatch(be.program(MERGE), group_count(grid.dims, MERGE.local_size), uniforms={"dims": grid.dims},
                    samplers=samplers, images=self.volumes)
        return self.volumes
