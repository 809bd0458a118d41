"""Voxelization pass (shared by VCT, LPV's geometry volume and voxel visibility).

Inputs: scene triangles; a Grid. Outputs (RGBA32F 3D textures of grid.dims, canonical x, y, z layout):
`vox_albedo` (diffuse albedo toward other surfaces, Scene.bounce_albedo; a = occupancy 0/1),
`vox_normal` (area-weighted mean normal, w = surface area in the cell in cell units^2), `vox_emission`
(emitted radiance W/m^2/sr, a = occupancy),
`vox_projected` (xyz = per axis the larger of the areas the surfaces facing + and - project along it,
in cell units^2: a one-sided wall its area, both faces of a thin wall one of them, a closed column its
silhouette; unlike the mean normal it does not cancel in thin walls: VCT's directional opacity and
LPV's blocking; w = surface area), `vox_offset` (xyz = per axis the area-weighted mean offset from the
cell's centre, in cells (-0.5..0.5), of the surfaces voxelized along that axis, 0 where there are
none: where in its cell a wall lies; the raster pass sums depth x weight in emission's alpha).

Portable scatter (ARCHITECTURE.md section 3): each triangle is drawn along its dominant axis into the
layers of that axis's volumes with additive blending (conservative coverage, see voxelize.vert.glsl),
one draw per slab; a compute pass merges the three axis volumes and divides out the weights.
Mavridis et al. slice the same way; the thesis in seeds/ (003) used a geometry shader instead.

Incremental updates (`Voxelizer.update`): when an object moves, only the slabs its triangles reached
before or reach now can change, so only those layers' meshes are rebuilt and only those layers are
cleared and redrawn; the other layers of the axis volumes keep their previous contents. A rebuilt layer
holds the same triangles in the same order as a full `set_scene` would give it and blending adds the
same fragments in the same (primitive) order, so the result is bitwise that of a full voxelization.
A different triangle count gives no row correspondence to compare: it falls back to `set_scene`.
"""

from __future__ import annotations

import numpy as np

from ..backends.base import Backend, Image, Sampler, ShaderSpec, Var, group_count
from ..grid import Grid
from ..scene import Scene
from . import zero
from .declare import TRIANGLES, VOXELS, PassDecl

_UNIFORMS = (Var("grid_origin", "vec3"), Var("cell_size", "float"), Var("dims", "ivec3"), Var("axis", "int"),
             Var("layer", "int"))

RASTER = ShaderSpec(
    name="voxelize",
    vertex="voxelize/voxelize.vert.glsl",
    fragment="voxelize/voxelize.frag.glsl",
    uniforms=_UNIFORMS,
    attributes=(Var("pos_ws", "vec3"), Var("next_ws", "vec3"), Var("prev_ws", "vec3"), Var("tri_normal", "vec3"),
                Var("albedo", "vec3"), Var("emission", "vec3")),
    varyings=(Var("v_uvw", "vec3"), Var("v_plane", "vec4"), Var("v_bbox", "vec4"), Var("v_wrange", "vec2"),
              Var("v_corners01", "vec4"), Var("v_corner2", "vec2"),
              Var("v_albedo", "vec3"), Var("v_emission", "vec3"), Var("v_normal", "vec3")),
    outputs=(Var("out_albedo", "vec4"), Var("out_normal", "vec4"), Var("out_emission", "vec4"),
             Var("out_projected", "vec4")),
)

_QUANTITIES = ("albedo", "normal", "emission", "projected")
# The merge also writes vox_offset, from the depths the raster pass sums in emission's alpha.
_MERGED = (*_QUANTITIES, "offset")

MERGE = ShaderSpec(
    name="voxelize_merge",
    compute="voxelize/merge.comp.glsl",
    local_size=(4, 4, 4),
    samplers=tuple(Sampler(f"{q}_{a}", "3D") for q in _QUANTITIES for a in "xyz"),
    images=tuple(Image(f"vox_{q}", "3D") for q in _MERGED),
    uniforms=(Var("dims", "ivec3"),),
)

# Axis a's volume stores (u, v, w) = the grid coordinates permuted so w runs along a (its layers).
_PERMUTATION = ((1, 2, 0), (2, 0, 1), (0, 1, 2))


DECL = PassDecl("voxelize", "setup", (TRIANGLES,), VOXELS, "the scene's surfaces per cell of a grid")


def triangle_normals(positions: np.ndarray) -> np.ndarray:
    """Unit geometric normals (n, 3) from the winding; zero for degenerate triangles."""
    n = np.cross(positions[:, 1] - positions[:, 0], positions[:, 2] - positions[:, 0])
    length = np.linalg.norm(n, axis=1, keepdims=True)
    return np.where(length > 0, n / np.maximum(length, 1e-30), 0.0)


def dominant_axis(normals: np.ndarray) -> np.ndarray:
    return np.argmax(np.abs(normals), axis=1)


def slab_range(positions_m: np.ndarray, grid: Grid, axis: int) -> tuple[np.ndarray, np.ndarray]:
    """First and last layer along `axis` (int64 arrays (n,)) that each triangle (n, 3, 3) may write
    into: its extent along the axis in cells, widened by one cell each side (the fragment shader widens
    a triangle's depth by at most 0.5 (|n_u| + |n_v|) / |n_w| <= 1 cell for its dominant axis), clamped
    to the grid. A triangle goes into every slab it can reach, so nothing is lost."""
    w = (positions_m[:, :, axis] - grid.origin_m[axis]) / grid.cell_size_m
    first = np.clip(np.floor(w.min(axis=1) - 1.0), 0, grid.dims[axis] - 1).astype(np.int64)
    last = np.clip(np.floor(w.max(axis=1) + 1.0), 0, grid.dims[axis] - 1).astype(np.int64)
    return first, last


def slab_buckets(first_layer: np.ndarray, last_layer: np.ndarray) -> dict[int, np.ndarray]:
    """Layer -> the indices i (ascending) with first_layer[i] <= layer <= last_layer[i]."""
    counts = last_layer - first_layer + 1
    tri = np.repeat(np.arange(len(first_layer)), counts)
    layer = np.repeat(first_layer, counts) + (np.arange(counts.sum()) - np.repeat(np.cumsum(counts) - counts, counts))
    order = np.argsort(layer, kind="stable")
    tri, layer = tri[order], layer[order]
    bounds = np.flatnonzero(np.diff(layer, prepend=-1, append=-1))  # each run's start, and the end (layers >= 0)
    return {int(layer[b]): tri[b:e] for b, e in zip(bounds[:-1], bounds[1:], strict=True)}


def _runs(flags: np.ndarray) -> list[tuple[int, int]]:
    """(first, count) of each run of True in a bool array."""
    edges = np.flatnonzero(np.diff(np.r_[0, flags.astype(np.int8), 0]))
    return [(int(a), int(b - a)) for a, b in zip(edges[::2], edges[1::2], strict=True)]


class Voxelizer:
    """Allocates the axis and canonical volumes for a grid and voxelizes a scene into them; `update`
    re-voxelizes only the layers the changed triangles reach."""

    def __init__(self, backend: Backend, grid: Grid):
        self.backend, self.grid = backend, grid
        be = backend
        self.volumes = {f"vox_{q}": be.texture(grid.dims) for q in _MERGED}
        self._axis_volumes = []
        self._layer_targets = []
        for axis in range(3):
            size = tuple(grid.dims[i] for i in _PERMUTATION[axis])
            vols = {q: be.texture(size) for q in _QUANTITIES}
            self._axis_volumes.append(vols)
            self._layer_targets.append([be.target([(vols[q], k) for q in _QUANTITIES]) for k in range(size[2])])
        self._meshes: list[dict] = [{}, {}, {}]
        # Per axis, the layers the next run clears and redraws (all of them until a first run).
        self._dirty = [np.ones(grid.dims[axis], bool) for axis in range(3)]
        self.layers_drawn = 0  # layers cleared and redrawn by the last run (of sum(grid.dims))
        # The scene last given (copies: a caller may edit its arrays in place) and, per triangle, what
        # its meshes were built from: unit normal, dominant axis (-1: degenerate, not drawn) and the
        # first and last layer it reaches along that axis.
        self._positions_m: np.ndarray | None = None
        self._albedo = self._emission = self._normals = None
        self._axis = self._first_layer = self._last_layer = None

    def set_scene(self, scene: Scene) -> None:
        """Upload each triangle to its dominant axis, once per slab it can touch: three vertices carrying
        their neighbours. A draw per slab then rasterizes only the triangles near it (drawing every
        triangle into every slab cost Sponza's 67k triangles x 3 x 128 slabs: 60 ms on an H100)."""
        n = scene.triangle_count
        self._positions_m = np.array(scene.positions_m, np.float64)
        self._albedo, self._emission = np.array(scene.bounce_reflectance()), np.array(scene.emission)
        self._normals = np.zeros((n, 3))
        self._axis = np.full(n, -1, np.int64)
        self._first_layer, self._last_layer = np.zeros(n, np.int64), np.zeros(n, np.int64)
        self._classify(np.arange(n))
        self._meshes = [{}, {}, {}]
        every_layer = [np.ones(d, bool) for d in self.grid.dims]
        self._rebuild(every_layer)
        self._dirty = every_layer

    def update(self, scene: Scene) -> int:
        """Take `scene` (same grid) in place of the last one, rebuilding only the meshes of the layers
        that the triangles whose positions, albedo or emission changed reached before or reach now; the
        next run redraws just those. Returns the number of changed triangles (all of them when the
        triangle count differs, which falls back to `set_scene`)."""
        if self._positions_m is None or scene.triangle_count != len(self._positions_m):
            self.set_scene(scene)
            return scene.triangle_count
        pos = np.asarray(scene.positions_m, np.float64)
        albedo, emission = scene.bounce_reflectance(), np.asarray(scene.emission)
        changed = np.flatnonzero(np.any(pos != self._positions_m, axis=(1, 2))
                                 | np.any(albedo != self._albedo, axis=1)
                                 | np.any(emission != self._emission, axis=1))
        if changed.size == 0:
            return 0
        before = self._reach(changed)
        self._positions_m[changed] = pos[changed]
        self._albedo[changed], self._emission[changed] = albedo[changed], emission[changed]
        self._classify(changed)
        layers = [b | a for b, a in zip(before, self._reach(changed), strict=True)]
        self._rebuild(layers)
        for dirty, rebuilt in zip(self._dirty, layers, strict=True):
            dirty |= rebuilt
        return int(changed.size)

    def invalidate(self) -> None:
        """Make the next run clear and redraw every layer: what a change reaching everywhere costs (the
        GPU timings measure a full voxelization this way)."""
        for dirty in self._dirty:
            dirty[:] = True

    def _classify(self, tris: np.ndarray) -> None:
        """Normals, dominant axes and reached layers of triangles `tris` from the stored positions."""
        pos = self._positions_m[tris]
        normals = triangle_normals(pos)
        axes = np.where(np.any(normals != 0, axis=1), dominant_axis(normals), -1)
        self._normals[tris], self._axis[tris] = normals, axes
        for axis in range(3):
            on_axis = axes == axis
            first, last = slab_range(pos[on_axis], self.grid, axis)
            self._first_layer[tris[on_axis]], self._last_layer[tris[on_axis]] = first, last

    def _reach(self, tris: np.ndarray) -> list[np.ndarray]:
        """Per axis, a bool per layer: does one of triangles `tris` (as classified now) reach it?"""
        reach = []
        for axis in range(3):
            t = tris[self._axis[tris] == axis]
            steps = np.zeros(self.grid.dims[axis] + 1, np.int64)
            np.add.at(steps, self._first_layer[t], 1)
            np.add.at(steps, self._last_layer[t] + 1, -1)
            reach.append(np.cumsum(steps[:-1]) > 0)
        return reach

    def _rebuild(self, layers: list[np.ndarray]) -> None:
        """Rebuild the meshes of the layers flagged per axis: only the triangles reaching a flagged layer
        are bucketed, so each layer gets the triangles a full bucketing gives it, in ascending order."""
        prog = self.backend.program(RASTER)
        for axis in range(3):
            if not layers[axis].any():
                continue
            flagged_before = np.r_[0, np.cumsum(layers[axis])]  # flagged layers below each layer
            cand = np.flatnonzero(self._axis == axis)
            cand = cand[flagged_before[self._last_layer[cand] + 1] > flagged_before[self._first_layer[cand]]]
            buckets = slab_buckets(self._first_layer[cand], self._last_layer[cand])
            for layer in map(int, np.flatnonzero(layers[axis])):
                if layer not in buckets:
                    self._meshes[axis].pop(layer, None)
                    continue
                t = cand[buckets[layer]]
                p = self._positions_m[t]
                attrs = {
                    "pos_ws": p,
                    "next_ws": p[:, [1, 2, 0]],
                    "prev_ws": p[:, [2, 0, 1]],
                    "tri_normal": np.repeat(self._normals[t][:, None], 3, axis=1),
                    "albedo": np.repeat(self._albedo[t][:, None], 3, axis=1),
                    "emission": np.repeat(self._emission[t][:, None], 3, axis=1),
                }
                self._meshes[axis][layer] = self.backend.mesh(prog, {k: v.reshape(-1, 3) for k, v in attrs.items()},
                                                              "triangles")

    def run(self) -> dict:
        """Clear and redraw the layers changed since the last run, then merge the whole grid."""
        be, grid = self.backend, self.grid
        prog = be.program(RASTER)
        uniforms = {"grid_origin": grid.origin_m, "cell_size": grid.cell_size_m, "dims": grid.dims}
        self.layers_drawn = 0
        for axis in range(3):
            volumes = [self._axis_volumes[axis][q] for q in _QUANTITIES]
            for first, count in _runs(self._dirty[axis]):
                zero.layers(be, volumes, first, count)
            for k in map(int, np.flatnonzero(self._dirty[axis])):
                mesh = self._meshes[axis].get(k)
                if mesh is not None:
                    be.draw(prog, self._layer_targets[axis][k], mesh, uniforms={**uniforms, "axis": axis, "layer": k},
                            blend="add")
            self.layers_drawn += int(self._dirty[axis].sum())
            self._dirty[axis][:] = False
        samplers = {f"{q}_{'xyz'[a]}": self._axis_volumes[a][q] for q in _QUANTITIES for a in range(3)}
        be.dispatch(be.program(MERGE), group_count(grid.dims, MERGE.local_size), uniforms={"dims": grid.dims},
                    samplers=samplers, images=self.volumes)
        return self.volumes
