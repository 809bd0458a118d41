"""Method `lpv`: light propagation volume (Kaplanyan 2009, CLPV Kaplanyan & Dachsbacher 2010; seeds 002).

Passes: those of `direct` (G-buffer, per light face: rsm, direct_light), then per RSM face while it is
bound: lpv_inject (VPLs splatted into a 2D atlas of the grid's layers); once per update after every
face: lpv_inject.unpack (atlas -> 3D snapshot), N x lpv_propagate (ping-pong, accumulated), lpv_lookup
-> `indirect` (Cycles' Diffuse Indirect units; improved + geometry volume: geometry-aware corners).
With LpvConfig.geometry_volume the scene is voxelized once per geometry change on the LPV grid and the
area its surfaces project along each axis blocks the transfers (with surface_offsets, those on the
surfaces' side of the cell's centre). GIConfig.bounces = k > 1 adds k - 1 bounces after
the first bounce's lookup, each: lpv_reinject (the voxelized surfaces reflect the previous bounce's
light into a fresh snapshot), N x lpv_propagate into a per-bounce accumulation, lpv_lookup added to
`indirect`, lpv_reinject.add into the total; these need the voxelizer's albedo and normals, so it runs
whenever bounces > 1 (it blocks propagation only with geometry_volume). Over cascades every grid
re-injects and propagates each bounce, coarsest first, with its parent's inflow of that bounce. docs/LPV.md derives the
normalisation and measures both variants against Cycles.

The grid is fitted to the uploaded (re-centred) geometry: Grid.fit(bounds, max_cells=grid_cells),
non-cubic for flat scenes. With LpvConfig.cascades = C > 1 (lpv_cascade.place) that grid is the
coarsest of C nested ones, each finer one half the cell size around the camera (re-placed when the
camera leaves a parent cell, re-voxelized then). Every cascade gets the same VPLs; coarsest first, each
propagates on its own after lpv_cascade.inflow has added the light entering it from its parent; the
lookups run coarsest first, each finer one blended in across its band. With LpvConfig.far_field (improved,
>= 32 cells) the coarsest grid runs only its near steps and a far-field grid of twice its cell
(lpv_far_field: its own voxels and injection; later bounces' sources summed from the fine grid's) carries
the light further; its accumulation is added to the fine one. With emitter classes (LpvConfig.
emitter_classes, improved, one cascade: `uses_emitter_classes`) the atlases hold one block per class of
VPL normal, each class is unpacked and propagated on its own into `class_accumulated` and added to the
total, and lpv_lookup.own records each pixel's own class's reading, which the lookup subtracts from the
total's; with later bounces lpv_reinject.own records each surface side's own-class reading too, which
the second bounce's re-injection subtracts (later bounces propagate and look up their total). With the
octree variant (lpv_octree; improved transport) the coarsest grid is level 0 of a mip chain of
LpvConfig.octree_levels grids (`LpvVolume.octree`): every propagation of it (each bounce's) sums its
source snapshot down the chain, runs octree_iterations steps on every level and merges the levels into
its accumulation; it has no far field. Products: direct, indirect, albedo.
"""

from __future__ import annotations

import numpy as np

from .. import registry
from ..config import LpvConfig
from ..errors import ConfigError
from ..grid import Grid
from ..passes import (
    declare,
    lpv_cascade,
    lpv_far_field,
    lpv_inject,
    lpv_lookup,
    lpv_octree,
    lpv_propagate,
    lpv_reinject,
    rsm_reduce,
    voxelize,
    zero,
)
from ..passes.light_views import LightView
from ..passes.voxelize import Voxelizer
from .direct import OneBounceMethod


def transport(config: LpvConfig) -> str:
    """The propagation step's transfer (lpv_propagate's variants): the octree runs the improved one."""
    return "classic" if config.variant == "classic" else "improved"


def iterations_for(config: LpvConfig, grid: Grid) -> int:
    """Propagation steps. classic: config.iterations. improved (and the octree's finer cascades): at
    least the grid's Manhattan span (sum(dims) - 3, capped at 256): light moves one cell per step along
    one axis, so fewer steps cut it off before it has crossed the grid (BASELINE.md: light 'lost beyond
    ~12 cells'). The octree's mip chain runs octree_iterations on each level instead (LpvMethod.propagate)."""
    if transport(config) == "improved":
        return max(config.iterations, min(256, sum(grid.dims) - 3))
    return config.iterations


def near_steps_for(config: LpvConfig, grid: Grid) -> int:
    """The steps `grid` runs itself when a far field carries the rest (lpv_far_field), 0 when it has none:
    the improved variant with LpvConfig.far_field, on a grid of >= MIN_GRID_CELLS along its longest side;
    near_steps, or 0 for half that side's cells (measured: docs/LPV.md, "Far field"); none when the
    grid's own steps are no more than that."""
    if not (config.far_field and config.variant == "improved" and max(grid.dims) >= lpv_far_field.MIN_GRID_CELLS):
        return 0
    near = config.near_steps or max(grid.dims) // 2
    return near if near < iterations_for(config, grid) else 0


def uses_emitter_classes(config: LpvConfig) -> bool:
    """Emitter classes apply to the improved variant with one cascade (a finer cascade's inflow would need
    its parent's light per class)."""
    return config.emitter_classes and config.variant == "improved" and config.cascades == 1


class LpvVolume:
    """One grid's textures: snapshot sets (0 = the injection, kept for a finer cascade's inflow; 1 and 2
    ping-pong), the accumulation, the injection atlas, when asked for the voxels, its far-field grid
    (`far`, an LpvVolume made with far_field_of, or None) and the coarser levels of its octree
    (`octree`, each made with far_field_of = the level below; empty without). A far-field grid's (or
    octree level's) accumulation holds only its own propagation's light; it has no bounce
    accumulation, and with the geometry volume its voxels (projected areas and offsets only) are summed
    from its fine grid's, not voxelized."""

    def __init__(self, method: LpvMethod, cascade: lpv_cascade.Cascade, far_field_of: LpvVolume | None = None,
                 blocks: bool = True):
        be = method.backend
        self.blocks = blocks  # False: an octree level above LpvConfig.octree_blocked_levels (no geometry volume)
        self.cascade, self.grid = cascade, cascade.grid
        self.far_field_of = far_field_of
        is_far_field = far_field_of is not None
        dims = self.grid.dims
        self.snapshots = [{f"sh_{c}": be.texture(dims) for c in "rgb"} for _ in range(3)]
        self.accumulated = {f"acc_{c}": be.texture(dims) for c in "rgb"}
        classes = method.classes
        self.atlas, self.inject_atlas, self.inject_target = lpv_inject.atlas_target(be, self.grid, classes)
        # One emitter class's light (the far field adds its own into it; it needs none of its own), and
        # with later bounces each surface side's reading of its own class (lpv_reinject.own).
        self.class_accumulated = ({f"acc_{c}": be.texture(dims) for c in "rgb"}
                                  if classes and not is_far_field else None)
        self.own_reinject = ({k: be.texture(dims) for k in ("own_front", "own_back")}
                             if classes and not is_far_field and method.gi.bounces > 1 else None)
        # One bounce's accumulation (the total is `accumulated`): what the next bounce re-injects.
        self.bounce_accumulated = ({f"acc_{c}": be.texture(dims) for c in "rgb"}
                                   if method.gi.bounces > 1 and not is_far_field else None)
        self.geometry_volume = method.lpv_config.geometry_volume
        self.voxels = None
        self.blocking = None  # lpv_propagate.blocking's volumes, with the geometry volume
        self.far: LpvVolume | None = None
        self.octree: list[LpvVolume] = []
        self.voxelize(method)

    def voxelize(self, method: LpvMethod) -> None:
        cfg = method.lpv_config
        fine = self.far_field_of
        if not (cfg.geometry_volume or (method.gi.bounces > 1 and fine is None)) or not self.blocks:
            return
        if fine is not None:
            self.voxels = lpv_far_field.voxels(method.backend, fine.voxels, fine.grid, self.grid, self.voxels)
        else:
            self._voxelizer = Voxelizer(method.backend, self.grid)  # keeps its textures alive
            self._voxelizer.set_scene(method.scene)
            self.voxels = self._voxelizer.run()
        if cfg.geometry_volume:
            # Classic is the published scheme's baseline: its cells block half and half whatever the config.
            offsets = cfg.surface_offsets and transport(cfg) == "improved"
            self.blocking = lpv_propagate.blocking(method.backend, self.voxels, self.grid, offsets, self.blocking)
        for coarse in self.octree:  # each level's geometry from the one below's, finest first
            coarse.voxelize(method)

    def move(self, method: LpvMethod, cascade: lpv_cascade.Cascade) -> None:
        """The same dims at another place (the camera moved): re-voxelized; the atlas layout is unchanged."""
        self.cascade, self.grid = cascade, cascade.grid
        self.voxelize(method)

    @property
    def vox_normal(self):
        """The voxels' mean normals the geometry-aware lookup weighs its corners by (only with
        LpvConfig.geometry_volume; `blocking` is what blocks propagation; later bounces use the voxels
        as emitters either way)."""
        return self.voxels["vox_normal"] if self.voxels is not None and self.geometry_volume else None


class LpvMethod(OneBounceMethod):
    spec = registry.get("lpv")
    PASSES = declare.extend(
        OneBounceMethod.PASSES, setup=(voxelize.DECL, lpv_propagate.BLOCKING_DECL),
        # Per cascade, coarsest first: a finer one's inflow reads its parent's propagated light.
        solve=(lpv_cascade.PLACE_DECL, lpv_inject.DECL, lpv_propagate.DECL, lpv_cascade.INFLOW_DECL,
               lpv_far_field.DECL, lpv_octree.DECL),
        # With emitter classes the lookup's own-class readings need each class's propagation: the
        # gather runs them (propagate_classes); later bounces re-inject and propagate in the gather too.
        gather=(lpv_inject.DECL, lpv_propagate.DECL, lpv_lookup.DECL, lpv_reinject.DECL))

    def __init__(self, backend, gi, rsm_config, lpv_config: LpvConfig | None = None):
        super().__init__(backend, gi, rsm_config)
        self.lpv_config = lpv_config if lpv_config is not None else LpvConfig()
        self.levels: list[LpvVolume] = []
        self.classes = uses_emitter_classes(self.lpv_config)  # fixed with the config
        self.cell_steps = 0  # propagation work since the last solve began: cells x steps, over every grid

    # The finest grid's textures (the only grid when cascades = 1).
    grid = property(lambda self: self.levels[0].grid)
    snapshots = property(lambda self: self.levels[0].snapshots)
    accumulated = property(lambda self: self.levels[0].accumulated)
    bounce_accumulated = property(lambda self: self.levels[0].bounce_accumulated)
    atlas = property(lambda self: self.levels[0].atlas)
    inject_atlas = property(lambda self: self.levels[0].inject_atlas)
    voxels = property(lambda self: self.levels[0].voxels)
    vox_normal = property(lambda self: self.levels[0].vox_normal)

    def camera_m(self) -> np.ndarray:
        """The camera's position in the uploaded geometry's (re-centred) frame: where the cascades go.
        One grid fits the scene wherever the camera is, so a solve alone (no camera) needs one only
        with cascades."""
        if self.source.camera is None:
            if self.lpv_config.cascades > 1:
                raise ConfigError("LPV cascades are placed around the camera: a light field without a camera "
                                  "(a volume bake) takes one grid (cascades = 1)")
            return np.mean(self.bounds_m, axis=0)
        return self.source.camera.position_m - self.origin_m

    def place_cascades(self) -> list[lpv_cascade.Cascade]:
        cfg = self.lpv_config
        return lpv_cascade.place(*self.bounds_m, self.camera_m(), cfg.grid_cells, cfg.cascades, cfg.cell_size_m)

    def set_scene(self, scene) -> None:
        super().set_scene(scene)
        self.levels = [LpvVolume(self, c) for c in self.place_cascades()]
        top = self.levels[-1]
        if near_steps_for(self.lpv_config, top.grid):
            top.far = LpvVolume(self, lpv_cascade.Cascade(lpv_far_field.grid_for(top.grid)), far_field_of=top)
        if self.lpv_config.variant == "octree":
            below = top
            for i, grid in enumerate(lpv_octree.level_grids(top.grid, self.lpv_config.octree_levels), start=1):
                below = LpvVolume(self, lpv_cascade.Cascade(grid), far_field_of=below,
                                  blocks=i < self.lpv_config.octree_blocked_levels)
                top.octree.append(below)
        self._reduced: dict[int, tuple[int, dict | None]] = {}  # reduced_vpls' (factor, textures) per RSM size

    def allocate_products(self, size: tuple[int, int]) -> None:
        super().allocate_products(size)
        # A later bounce's lookup over cascades, before it is added to `indirect` (add_bounces).
        several = self.lpv_config.cascades > 1 and self.gi.bounces > 1
        self._bounce_image = self.backend.texture(size) if several else None
        # Emitter classes: each pixel's reading of its own class's light (lpv_lookup.own).
        self._own_light = self.backend.texture(size) if self.classes else None

    def follow_camera(self) -> None:
        """Re-place the finer cascades where the camera has moved to another parent cell."""
        for level, cascade in zip(self.levels, self.place_cascades(), strict=True):
            if (cascade.parent_offset, cascade.grid.dims) != (level.cascade.parent_offset, level.grid.dims):
                level.move(self, cascade)

    def lookup_vox(self, level: LpvVolume):
        """The improved variant's lookup skips the trilinear corners a surface blocks along its normal;
        classic keeps the published plain trilinear lookup (docs/LPV.md, "Lookup")."""
        return level.vox_normal if transport(self.lpv_config) == "improved" else None

    def grids(self) -> list[LpvVolume]:
        """Every grid that receives the VPLs: the cascades, finest first, then the far field if any."""
        far = self.levels[-1].far
        octree = self.levels[-1].octree if lpv_octree.injects(self.lpv_config.octree_merge) else []
        return self.levels + ([far] if far is not None else []) + octree

    def keeps_light_field(self) -> bool:
        """Cascades are placed around the camera (a camera move can move them: a new solve); later
        bounces add to each grid's accumulation in the gather (a second gather would add them twice)."""
        return super().keeps_light_field() and self.lpv_config.cascades == 1 and self.gi.bounces == 1

    def begin_solve(self, timings: dict[str, float]) -> None:
        self.cell_steps = 0
        if len(self.levels) > 1:
            with self.step(timings, lpv_cascade.PLACE_DECL):
                self.follow_camera()
        for level in self.grids():
            zero.images(self.backend, list(level.inject_atlas.values()))

    def solve_view(self, view: LightView, timings: dict[str, float]) -> None:
        with self.step(timings, lpv_inject.DECL):
            vpls, factor = self.reduced_vpls(view.resolution)
            points = self.rsm_points(view.resolution // factor, lpv_inject.spec(self.classes))
            for level in self.grids():
                lpv_inject.run(self.backend, level.inject_target, points, vpls, level.grid, level.atlas,
                               self.classes)

    def reduced_vpls(self, texels: int) -> tuple[dict, int]:
        """The face's VPLs (`self.rsm`, `texels` a side) as injected, and the factor its side was reduced by
        (rsm_reduce: about two VPLs per cell of the finest grid); the reduced textures are made once per size."""
        if texels not in self._reduced:
            factor = rsm_reduce.factor_for(texels, self.lpv_config.grid_cells)
            self._reduced[texels] = factor, rsm_reduce.textures(self.backend, texels, factor) if factor > 1 else None
        factor, textures = self._reduced[texels]
        if textures is None:
            return self.rsm, 1
        rsm_reduce.run(self.backend, self.rsm, textures, factor)
        return textures, factor

    def propagate(self, iterations: int | None = None, accumulated: dict | None = None,
                  level: LpvVolume | None = None) -> None:
        """Propagate a grid's (default: the finest's) snapshot set 0 into `accumulated` (default: its
        total), overwriting it; set 0 is kept. With a far field (whose snapshot set 0 the caller has
        filled too) the grid runs its near steps, the far field its own span, and its far light is added.
        With an octree, set 0 is summed down the mip chain, every level runs octree_iterations steps, and
        the levels are merged into `accumulated`. `iterations` overrides the config: that many steps on
        this grid alone."""
        level = self.levels[0] if level is None else level
        acc = level.accumulated if accumulated is None else accumulated
        if level.octree and iterations is None:
            self._propagate_octree(level, acc)
            return
        near = near_steps_for(self.lpv_config, level.grid) if level.far is not None and iterations is None else 0
        if not near:
            self._steps(level, iterations_for(self.lpv_config, level.grid) if iterations is None else iterations,
                        acc)
            return
        far = level.far
        # The fine grid's last step with a share is near - 1; at least one step initialises `acc`.
        self._steps(level, max(1, near - 1), acc, lambda step: lpv_far_field.fine_weight(step, near))
        self._steps(far, iterations_for(self.lpv_config, far.grid), far.accumulated,
                    lambda step: lpv_far_field.coarse_weight(step, near))
        lpv_far_field.add(self.backend, far.accumulated, far.grid, acc, level.grid)

    def fill_octree(self, level: LpvVolume, injected: bool) -> None:
        """The source snapshot (set 0) of every coarser level of `level`'s octree: unpacked from its own
        injection (`injected`: the first bounce of the time merge) or summed down from level 0's."""
        be, chain = self.backend, [level, *level.octree]
        for fine, coarse in zip(chain[:-1], chain[1:], strict=True):
            if injected:
                lpv_inject.unpack(be, coarse.inject_atlas, coarse.snapshots[0], coarse.grid, coarse.atlas)
            else:
                lpv_octree.downsample(be, fine.snapshots[0], fine.grid, coarse.snapshots[0], coarse.grid)

    def _propagate_octree(self, level: LpvVolume, acc: dict) -> None:
        """`level`'s octree (lpv_octree; every level's snapshot set 0 filled by fill_octree) propagated
        and merged into acc (overwritten)."""
        cfg, chain = self.lpv_config, [level, *level.octree]
        accs = [acc] + [coarse.accumulated for coarse in level.octree]
        k, n, mode = cfg.octree_iterations, len(chain), cfg.octree_merge
        span = min(256, sum(chain[-1].grid.dims) - 3)  # the coarsest level's Manhattan span
        for i, (lv, lv_acc) in enumerate(zip(chain, accs, strict=True)):
            share = (lambda step, i=i: lpv_octree.time_share(i, step, k, n)) if mode == "time" else None
            self._steps(lv, lpv_octree.steps(i, k, n, mode, span), lv_acc, share)
        for i in reversed(range(n - 1)):  # coarse to fine: each merge reads the merged level above
            lpv_octree.merge(self.backend, accs[i + 1], chain[i + 1].grid, accs[i], chain[i].grid, mode,
                             cfg.octree_epsilon)

    def work(self) -> dict[str, int]:
        """Propagation cell-steps (cells x steps summed over grids, levels and bounces): what the transport
        costs independently of the machine (docs/LPV.md's octree table)."""
        return {"propagation_cell_steps": self.cell_steps}

    def _steps(self, level: LpvVolume, n: int, acc: dict, share=None) -> None:
        """n propagation steps of `level` from its snapshot set 0, accumulated into acc (overwritten),
        step s (1-based) weighted by share(s) when given."""
        sets = level.snapshots
        self.cell_steps += n * int(np.prod(level.grid.dims))
        for i in range(n):
            src = sets[0] if i == 0 else sets[2 - i % 2]
            lpv_propagate.run(self.backend, src, sets[1 + i % 2], acc, level.grid, transport(self.lpv_config),
                              first_step=i == 0, geometry=level.blocking,
                              step_scale=1.0 if share is None else share(i + 1))

    def add_bounces(self, timings: dict[str, float], look_up: bool = True) -> None:
        """Bounces 2..gi.bounces on top of the first bounce (in each grid's `accumulated` and in
        `indirect`). Each: every grid, coarsest first, re-injects what its surfaces reflect of the
        previous bounce and propagates it into its `bounce_accumulated` (a finer cascade after its
        parent's inflow of the same bounce, as for the first); the bounce is looked up on its own (clamped
        at 0 by itself, so none takes light away) and added to `indirect`, and each grid's bounce to its
        `accumulated`, the total a volume bake reads. Afterwards `bounce_accumulated` holds the last
        bounce alone."""
        be, levels = self.backend, self.levels
        previous = [level.accumulated for level in levels]  # each holds bounce 1 alone until the first add
        for bounce in range(self.gi.bounces - 1):
            for i in reversed(range(len(levels))):
                level = levels[i]
                with self.step(timings, lpv_reinject.DECL):
                    # With emitter classes the first bounce's surfaces reflect the other classes' light.
                    lpv_reinject.run(be, previous[i], level.voxels, level.snapshots[0], level.grid,
                                     own=level.own_reinject if bounce == 0 else None)
                    if i + 1 < len(levels):
                        parent = levels[i + 1]
                        lpv_cascade.inflow(be, level.cascade, level.snapshots[0], parent.grid,
                                           parent.bounce_accumulated, parent.snapshots[0], transport(self.lpv_config))
                    if level.far is not None:
                        lpv_far_field.source(be, level.snapshots[0], level.grid, level.far.snapshots[0],
                                             level.far.grid)
                    if level.octree:  # the re-injected light summed down the mip chain
                        self.fill_octree(level, injected=False)
                with self.step(timings, lpv_propagate.DECL):
                    self.propagate(accumulated=level.bounce_accumulated, level=level)
            if look_up:
                with self.step(timings, lpv_lookup.DECL):
                    if len(levels) == 1:
                        lpv_lookup.run(be, self.gbuf, levels[0].bounce_accumulated, self.indirect, levels[0].grid,
                                       accumulate=True, vox_normal=self.lookup_vox(levels[0]))
                    else:
                        self.look_up(lambda level: level.bounce_accumulated, self._bounce_image)
                        lpv_lookup.add_image(be, self._bounce_image, self.indirect)
            with self.step(timings, lpv_reinject.DECL):
                for level in levels:
                    lpv_reinject.add(be, level.bounce_accumulated, level.accumulated, level.grid)
            previous = [level.bounce_accumulated for level in levels]

    def look_up(self, volume_of, out) -> None:
        """`out` from every grid's volume_of(level), coarsest first, each finer cascade blended in."""
        for i in reversed(range(len(self.levels))):
            level = self.levels[i]
            lpv_lookup.run(self.backend, self.gbuf, volume_of(level), out, level.grid,
                           vox_normal=self.lookup_vox(level),
                           cascade=level.cascade if i + 1 < len(self.levels) else None)

    def propagate_levels(self, timings: dict[str, float]) -> None:
        """The first bounce without emitter classes: every grid's injection unpacked and propagated into
        its `accumulated`."""
        be = self.backend
        # Coarsest first: a finer cascade's inflow reads its parent's propagated light.
        for i in reversed(range(len(self.levels))):
            level = self.levels[i]
            with self.step(timings, lpv_inject.DECL):
                lpv_inject.unpack(be, level.inject_atlas, level.snapshots[0], level.grid, level.atlas)
                if level.far is not None:
                    far = level.far
                    lpv_inject.unpack(be, far.inject_atlas, far.snapshots[0], far.grid, far.atlas)
                if level.octree:
                    self.fill_octree(level, injected=lpv_octree.injects(self.lpv_config.octree_merge))
                if i + 1 < len(self.levels):
                    parent = self.levels[i + 1]
                    lpv_cascade.inflow(be, level.cascade, level.snapshots[0], parent.grid, parent.accumulated,
                                       parent.snapshots[0], transport(self.lpv_config))
            with self.step(timings, lpv_propagate.DECL):
                if len(self.levels) > 1:
                    with self.timed(timings, f"lpv_propagate_cascade{i}"):
                        self.propagate(level=level)
                else:
                    self.propagate(level=level)

    def propagate_classes(self, timings: dict[str, float], look_up: bool = True) -> None:
        """The first bounce with emitter classes (one grid, and its far field if any): each class
        unpacked, propagated into `class_accumulated`, added to `accumulated`, and (look_up) its reading
        at the pixels of that class recorded; then the lookup reads the total less each pixel's own class.
        Without look_up only the total is built (a volume bake: no pixels)."""
        be, level = self.backend, self.levels[0]
        zero.layers(be, list(level.accumulated.values()), 0, level.grid.dims[2])
        for emitter in range(lpv_inject.CLASSES):
            with self.step(timings, lpv_inject.DECL):
                lpv_inject.unpack(be, level.inject_atlas, level.snapshots[0], level.grid, level.atlas, emitter)
                if level.far is not None:
                    far = level.far
                    lpv_inject.unpack(be, far.inject_atlas, far.snapshots[0], far.grid, far.atlas, emitter)
            with self.step(timings, lpv_propagate.DECL):
                self.propagate(accumulated=level.class_accumulated, level=level)
                lpv_reinject.add(be, level.class_accumulated, level.accumulated, level.grid)
            if look_up:
                with self.step(timings, lpv_lookup.DECL):
                    lpv_lookup.own(be, self.gbuf, level.class_accumulated, self._own_light, level.grid, emitter,
                                   vox_normal=self.lookup_vox(level))
            if level.own_reinject is not None:
                with self.step(timings, lpv_reinject.DECL):
                    lpv_reinject.own(be, level.class_accumulated, level.voxels, level.own_reinject, level.grid,
                                     emitter)
        if look_up:
            with self.step(timings, lpv_lookup.DECL):
                lpv_lookup.run(be, self.gbuf, level.accumulated, self.indirect, level.grid,
                               vox_normal=self.lookup_vox(level), own_light=self._own_light)

    def finish_solve(self, timings: dict[str, float]) -> None:
        """The first bounce's propagation; with emitter classes the gather propagates each class itself
        (its own-light lookups need each class's volume, which one propagation overwrites)."""
        if not self.classes:
            self.propagate_levels(timings)

    def gather_pixels(self, timings: dict[str, float]) -> None:
        if self.classes:
            self.propagate_classes(timings)
        else:
            with self.step(timings, lpv_lookup.DECL):
                self.look_up(lambda level: level.accumulated, self.indirect)
        self.add_bounces(timings)

    def solve_volume(self) -> dict[str, float]:
        """The light field alone, no pixels (a volume bake): every grid's `accumulated` holds the light
        of every bounce. What the gather adds to it (emitter classes, later bounces) runs without its
        lookups."""
        timings = self.solve_light_field()
        if self.classes:
            self.propagate_classes(timings, look_up=False)
        self.add_bounces(timings, look_up=False)
        self._solved_for = None  # `accumulated` now holds more than a gather expects: solve again first
        return timings
