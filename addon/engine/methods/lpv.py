"""Method `lpv`: light propagation volume (Kaplanyan 2009, CLPV Kaplanyan & Dachsbacher 2010; seeds 002).

Passes: those of `direct` (G-buffer, per light face: rsm, direct_light), then per RSM face while it is
bound: lpv_inject (VPLs splatted into a 2D atlas of the grid's layers); once per update after every
face: lpv_inject.unpack (atlas -> 3D snapshot), N x lpv_propagate (ping-pong, accumulated), lpv_lookup
-> `indirect` (Cycles' Diffuse Indirect units; improved + geometry volume: geometry-aware corners).
With LpvConfig.geometry_volume the scene is voxelized once per geometry change on the LPV grid and the
voxels' surface area x |n.d| blocks each transfer. GIConfig.bounces = k > 1 adds k - 1 bounces after
the first bounce's lookup, each: lpv_reinject (the voxelized surfaces reflect the previous bounce's
light into a fresh snapshot), N x lpv_propagate into a per-bounce accumulation, lpv_lookup added to
`indirect`, lpv_reinject.add into the total; these need the voxelizer's albedo and normals, so it runs
whenever bounces > 1 (it blocks propagation only with geometry_volume). docs/LPV.md derives the
normalisation and measures both variants against Cycles.

The grid is fitted to the uploaded (re-centred) geometry: Grid.fit(bounds, max_cells=grid_cells),
non-cubic for flat scenes. Products: direct, indirect, albedo.
"""

from __future__ import annotations

from ..config import LpvConfig
from ..grid import Grid
from ..passes import lpv_inject, lpv_lookup, lpv_propagate, lpv_reinject
from ..passes.light_views import LightView
from ..passes.voxelize import Voxelizer
from .direct import OneBounceMethod


def iterations_for(config: LpvConfig, grid: Grid) -> int:
    """Propagation steps. classic: config.iterations. improved: at least the grid's Manhattan span
    (sum(dims) - 3, capped at 256): light moves one cell per step along one axis, so fewer steps cut
    it off before it has crossed the grid (BASELINE.md: light 'lost beyond ~12 cells')."""
    if config.variant == "improved":
        return max(config.iterations, min(256, sum(grid.dims) - 3))
    return config.iterations


class LpvMethod(OneBounceMethod):
    name = "lpv"
    max_bounces = 8  # GIConfig's limit: each bounce is one more re-injection and propagation

    def __init__(self, backend, gi, rsm_config, lpv_config: LpvConfig | None = None):
        super().__init__(backend, gi, rsm_config)
        self.lpv_config = lpv_config if lpv_config is not None else LpvConfig()
        self.grid: Grid | None = None

    def set_scene(self, scene) -> None:
        super().set_scene(scene)
        be, cfg = self.backend, self.lpv_config
        self.grid = Grid.fit(*self.bounds_m, max_cells=cfg.grid_cells)
        dims = self.grid.dims
        # Two snapshot sets (ping-pong; set 0 receives the injection) and the accumulation.
        self.snapshots = [{f"sh_{c}": be.texture(dims) for c in "rgb"} for _ in range(2)]
        self.accumulated = {f"acc_{c}": be.texture(dims) for c in "rgb"}
        self.atlas, self.inject_atlas, self._inject_target = lpv_inject.atlas_target(be, self.grid)
        self._points = lpv_inject.texel_points(be, self.rsm_config.resolution)
        self.voxels = None
        if cfg.geometry_volume or self.gi.bounces > 1:
            voxelizer = Voxelizer(be, self.grid)
            voxelizer.set_scene(self.scene)
            self.voxels = voxelizer.run()
            self._voxelizer = voxelizer  # keeps its textures alive
        # Blocks propagation only when asked to; later bounces use the voxels as emitters either way.
        self.vox_normal = self.voxels["vox_normal"] if cfg.geometry_volume else None
        # The improved variant's lookup skips the trilinear corners a surface blocks along its normal;
        # classic keeps the published plain trilinear lookup (docs/LPV.md, "Lookup").
        self._lookup_vox = self.vox_normal if cfg.variant == "improved" else None
        # One bounce's accumulation (the total is `accumulated`): what the next bounce re-injects.
        self.bounce_accumulated = ({f"acc_{c}": be.texture(dims) for c in "rgb"} if self.gi.bounces > 1
                                   else None)

    def clear_products(self) -> None:
        super().clear_products()
        self.backend.clear(self._inject_target)

    def per_light_view(self, view: LightView, timings: dict[str, float]) -> None:
        with self.timed(timings, "lpv_inject"):
            lpv_inject.run(self.backend, self._inject_target, self._points, self.rsm, self.grid, self.atlas)

    def propagate(self, iterations: int | None = None, accumulated: dict | None = None) -> None:
        """Propagate the injected snapshot (set 0) into `accumulated` (default: the total), overwriting
        it; `iterations` overrides the config."""
        n = iterations_for(self.lpv_config, self.grid) if iterations is None else iterations
        acc = self.accumulated if accumulated is None else accumulated
        for i in range(n):
            lpv_propagate.run(self.backend, self.snapshots[i % 2], self.snapshots[(i + 1) % 2], acc,
                              self.grid, self.lpv_config.variant, first_step=i == 0, vox_normal=self.vox_normal)

    def reinject(self, previous: dict) -> None:
        """The light the surfaces reflect of one bounce's accumulation -> snapshot set 0 (overwritten)."""
        lpv_reinject.run(self.backend, previous, self.voxels["vox_normal"], self.voxels["vox_albedo"],
                         self.snapshots[0], self.grid)

    def add_bounces(self, timings: dict[str, float]) -> None:
        """Bounces 2..gi.bounces on top of the first bounce (in `accumulated` and `indirect`): each is
        looked up on its own and added to `indirect` (clamped per bounce, so none takes light away),
        and added to `accumulated`, the total a volume bake reads. Afterwards `bounce_accumulated`
        holds the last bounce alone."""
        be, grid = self.backend, self.grid
        previous = self.accumulated  # holds bounce 1 alone until the first add
        for _ in range(self.gi.bounces - 1):
            with self.timed(timings, "lpv_reinject"):
                self.reinject(previous)
            with self.timed(timings, "lpv_propagate"):
                self.propagate(accumulated=self.bounce_accumulated)
            with self.timed(timings, "lpv_lookup"):
                lpv_lookup.run(be, self.gbuf, self.bounce_accumulated, self.indirect, grid, accumulate=True,
                               vox_normal=self._lookup_vox)
            with self.timed(timings, "lpv_reinject"):
                lpv_reinject.add(be, self.bounce_accumulated, self.accumulated, grid)
            previous = self.bounce_accumulated

    def compute(self, run_gbuffer: bool = True) -> dict[str, float]:
        be = self.backend
        timings: dict[str, float] = {}
        with self.timed(timings, "total"):
            inner = super().compute(run_gbuffer)
            inner.pop("total", None)
            timings.update(inner)
            with self.timed(timings, "lpv_inject"):
                lpv_inject.unpack(be, self.inject_atlas, self.snapshots[0], self.grid, self.atlas)
            with self.timed(timings, "lpv_propagate"):
                self.propagate()
            with self.timed(timings, "lpv_lookup"):
                lpv_lookup.run(be, self.gbuf, self.accumulated, self.indirect, self.grid, vox_normal=self._lookup_vox)
            self.add_bounces(timings)
        return timings
