"""Method `lpv`: light propagation volume (Kaplanyan 2009, CLPV Kaplanyan & Dachsbacher 2010; seeds 002).

Passes: those of `direct` (G-buffer, per light face: rsm, direct_light), then per RSM face while it is
bound: lpv_inject; once per update after every face: N x lpv_propagate (ping-pong, accumulated),
lpv_lookup -> `indirect` (Cycles' Diffuse Indirect units). With LpvConfig.geometry_volume the scene is
voxelized once per geometry change on the LPV grid and the voxels' surface area x |n.d| blocks each
transfer. docs/LPV.md derives the normalisation and measures both variants against Cycles.

The grid is fitted to the uploaded (re-centred) geometry: Grid.fit(bounds, max_cells=grid_cells),
non-cubic for flat scenes. Products: direct, indirect, albedo.
"""

from __future__ import annotations

from ..config import LpvConfig
from ..grid import Grid
from ..passes import lpv_inject, lpv_lookup, lpv_propagate
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

    def __init__(self, backend, gi, rsm_config, lpv_config: LpvConfig | None = None):
        super().__init__(backend, gi, rsm_config)
        self.lpv_config = lpv_config if lpv_config is not None else LpvConfig()
        self.grid: Grid | None = None

    def set_scene(self, scene) -> None:
        super().set_scene(scene)
        be, cfg = self.backend, self.lpv_config
        self.grid = Grid.fit(*self.scene.bounds_m(), max_cells=cfg.grid_cells)
        dims = self.grid.dims
        # Two snapshot sets (ping-pong; set 0 receives the injection) and the accumulation.
        self.snapshots = [{f"sh_{c}": be.texture(dims) for c in "rgb"} for _ in range(2)]
        self.accumulated = {f"acc_{c}": be.texture(dims) for c in "rgb"}
        self._inject_targets = lpv_inject.layer_targets(be, self.snapshots[0], self.grid)
        self._points = lpv_inject.texel_points(be, self.rsm_config.resolution)
        self.vox_normal = None
        if cfg.geometry_volume:
            voxelizer = Voxelizer(be, self.grid)
            voxelizer.set_scene(self.scene)
            self.vox_normal = voxelizer.run()["vox_normal"]
            self._voxelizer = voxelizer  # keeps its textures alive

    def clear_products(self) -> None:
        super().clear_products()
        for target in self._inject_targets:
            self.backend.clear(target)

    def per_light_view(self, view: LightView, timings: dict[str, float]) -> None:
        with self.timed(timings, "lpv_inject"):
            lpv_inject.run(self.backend, self._inject_targets, self._points, self.rsm, self.grid)

    def propagate(self, iterations: int | None = None) -> None:
        """Propagate the injected snapshot (set 0) and accumulate; `iterations` overrides the config."""
        n = iterations_for(self.lpv_config, self.grid) if iterations is None else iterations
        for i in range(n):
            lpv_propagate.run(self.backend, self.snapshots[i % 2], self.snapshots[(i + 1) % 2], self.accumulated,
                              self.grid, self.lpv_config.variant, first_step=i == 0, vox_normal=self.vox_normal)

    def compute(self, run_gbuffer: bool = True) -> dict[str, float]:
        be = self.backend
        timings: dict[str, float] = {}
        with self.timed(timings, "total"):
            inner = super().compute(run_gbuffer)
            inner.pop("total", None)
            timings.update(inner)
            with self.timed(timings, "lpv_propagate"):
                self.propagate()
            with self.timed(timings, "lpv_lookup"):
                lpv_lookup.run(be, self.gbuf, self.accumulated, self.indirect, self.grid)
        return timings
