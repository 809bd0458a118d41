"""Method `vct`: voxel cone tracing (Crassin et al. 2011; seeds 003), dense pyramid, N diffuse bounces.

Passes: those of `direct` (G-buffer, per light face: rsm, direct_light), then per RSM face while it is
bound: vct_inject.run (VPL flux and surfel areas into a light's scratch atlas), per light
vct_inject.add_light (into the flux atlas, capped where a footprint overhangs the geometry); once per
update: vct_pyramid.level0 + downsample, and for
each bounce after the first: vct_gather.bounce (voxels gather and re-emit) -> accumulate -> a pyramid
of that bounce alone for the next; finally the pyramid of every bounce's light and vct_gather.pixels
-> `indirect` (Cycles' Diffuse Indirect units) and `ao`, and vct_gather.glossy -> `glossy` (the light
glossy lobes reflect, cones sampling each GGX lobe: Cycles' Glossy Color x Glossy Indirect). The scene is
voxelized per geometry change (set_scene): only the slabs that changed triangles reach, while the grid
(fitted to the bounds) stays the same. docs/VCT.md derives the units and measures the settings.

Products: direct, indirect, ao, albedo, glossy.
"""

from __future__ import annotations

import numpy as np

from .. import registry
from ..config import VctConfig
from ..grid import Grid
from ..passes import (
    accumulate,
    declare,
    denoise,
    rsm,
    sky_light,
    surface_support,
    vct_gather,
    vct_inject,
    vct_pyramid,
    voxelize,
    zero,
)
from ..passes.atlas import Atlas
from ..passes.light_views import LightView
from ..passes.vct_inject import DIRECTIONS
from ..passes.voxelize import Voxelizer
from .direct import SKY_DIRECTIONS_LEAST, OneBounceMethod


class VctMethod(OneBounceMethod):
    spec = registry.get("vct")
    PASSES = declare.extend(OneBounceMethod.PASSES, setup=(voxelize.DECL,),
                            solve=(vct_inject.DECL, sky_light.RSM_DECL, vct_inject.SKY_DECL, vct_pyramid.DECL,
                                   vct_gather.BOUNCE_DECL, vct_pyramid.DECL),
                            gather=(surface_support.DECL, vct_gather.PIXELS_DECL, vct_gather.GLOSSY_DECL,
                                    accumulate.DECL, denoise.DECL))
    NOISY = ("indirect", "ao", "glossy")
    # The world's bounce: the camera's sky directions, each an RSM tile of the sky atlas, injected at
    # once (inject_sky), not RsmConfig.world_suns suns one RSM and injection each (docs/VCT.md).
    WORLD_SUN_RSMS = False

    def __init__(self, backend, gi, rsm_config, vct_config: VctConfig | None = None):
        super().__init__(backend, gi, rsm_config)
        self.vct_config = vct_config if vct_config is not None else VctConfig()
        self.grid: Grid | None = None

    def set_scene(self, scene) -> None:
        """Upload the scene; when its bounds (so the grid) did not change, as when an object moves inside
        a room, the voxelizer redraws only the slabs the changed triangles reach (bitwise the same
        volumes, tests/gpu/test_voxelize.py) and the grid's other textures are kept."""
        super().set_scene(scene)
        be, cfg = self.backend, self.vct_config
        bounce = self.scene.bounce_reflectance()
        self._albedo_max = float(bounce.max()) if len(bounce) else 0.0
        self._glossy_anywhere = bool(np.any(self.scene.specular_f0() > 0))  # known_zero, once per geometry
        grid = Grid.fit(*self.bounds_m, max_cells=cfg.voxel_cells)
        if grid.same_cells(self.grid):
            self.voxelizer.update(self.scene)
            self.voxels = self.voxelizer.run()
            return
        self.grid = grid
        self.voxelizer = Voxelizer(be, self.grid)
        self.voxelizer.set_scene(self.scene)
        self.voxels = self.voxelizer.run()
        self.atlas = Atlas.for_grid(self.grid)
        self.flux = vct_pyramid.direction_textures(be, self.atlas.size)
        # One light's VPLs (all its RSM faces) before vct_inject.add_light adds them to `flux`.
        self.light_flux = vct_pyramid.direction_textures(be, self.atlas.size)
        self._light_target = be.target([self.light_flux[d] for d in DIRECTIONS])
        self._pending_light: int | None = None
        self.pyramid = vct_pyramid.pyramid_textures(be, self.grid)
        if self.gi.bounces > 1:
            self.next_bounce = vct_pyramid.direction_textures(be, self.grid.dims)
            self.later_bounces = vct_pyramid.direction_textures(be, self.grid.dims)

    def allocate_products(self, size: tuple[int, int]) -> None:
        super().allocate_products(size)
        self._lobe_albedo = vct_gather.split_albedo_texture(self.backend)
        scale = self.vct_config.gather_scale
        low = vct_gather.low_size(size, scale)
        self._low = (self.backend.texture(low), self.backend.texture(low)) if scale > 1 else None

    def begin_solve(self, timings: dict[str, float]) -> None:
        zero.images(self.backend, [self.flux[d] for d in DIRECTIONS])
        if self._pending_light is not None:  # an update left unfinished; _flush_light zeroes it otherwise
            zero.images(self.backend, [self.light_flux[d] for d in DIRECTIONS])
        self._pending_light = None

    def solve_view(self, view: LightView, timings: dict[str, float]) -> None:
        """Views come grouped by light: a new light first hands the previous one's VPLs to `flux`."""
        with self.step(timings, vct_inject.DECL):
            if self._pending_light is not None and view.light_index != self._pending_light:
                self._flush_light()
            filtered = self.vct_config.filtered_injection
            points = self.rsm_points(view.resolution, vct_inject.spec(filtered), vct_inject.points_per_texel(filtered))
            vct_inject.run(self.backend, self._light_target, points, self.rsm, self.grid, self.atlas,
                           self.voxels["vox_projected"] if filtered else None)
            self._pending_light = view.light_index

    def _flush_light(self) -> None:
        """The pending light's scratch atlas, capped by the voxelized geometry, added to `flux`."""
        vct_inject.add_light(self.backend, self.light_flux, self.flux, self.voxels["vox_projected"], self.grid,
                             self.atlas)
        zero.images(self.backend, [self.light_flux[d] for d in DIRECTIONS])
        self._pending_light = None

    def _build(self, atlas_weight: float, add: dict | None) -> None:
        be, iso = self.backend, self.vct_config.radiance == "isotropic"
        vct_pyramid.level0(be, self.flux, self.voxels["vox_projected"], self.pyramid, self.grid, self.atlas,
                           self.radiance_scale, atlas_weight, add, iso)
        vct_pyramid.downsample(be, self.pyramid, self.grid)

    def bounce_light(self, timings: dict[str, float]) -> None:
        """The pyramid of every bounce's light: the first from the injected flux; each later one gathered
        at the voxels from a pyramid of the bounce before it alone (so none is counted twice)."""
        be, cfg = self.backend, self.vct_config
        # Lights may change between updates (set_lights); the geometry's largest albedo only with set_scene.
        lights = [*self.source.lights, *self.emissive, *self.world_suns()]
        self.radiance_scale = vct_pyramid.radiance_scale(lights, self.bounds_m, self.grid.cell_size_m, self.gi.bounces,
                                                         self._albedo_max)
        with self.step(timings, vct_pyramid.DECL):
            self._build(1.0, None)
        if self.gi.bounces == 1:
            return
        for bounce in range(2, self.gi.bounces + 1):
            with self.step(timings, vct_gather.BOUNCE_DECL):
                vct_gather.bounce(be, self.pyramid, self.radiance_scale, self.voxels, self.next_bounce, self.grid,
                                  cfg, self.gi.seed + bounce)
                vct_pyramid.accumulate(be, self.later_bounces, self.next_bounce, self.grid, first=bounce == 2)
            with self.step(timings, vct_pyramid.DECL):
                if bounce < self.gi.bounces:
                    self._build(0.0, self.next_bounce)
                else:
                    self._build(1.0, self.later_bounces)

    def finish_solve(self, timings: dict[str, float]) -> None:
        if self._pending_light is not None:
            with self.step(timings, vct_inject.DECL):
                self._flush_light()
        self.inject_sky(timings)
        self.bounce_light(timings)

    def inject_sky(self, timings: dict[str, float]) -> None:
        """The world's VPLs: every sky direction's RSM into its tile (sky_rsm), all tiles splatted and
        capped as one light (each tile's surfel areas weighted by its share of the sky's power,
        sky_light.table, so a surface every direction lights counts its area once); nothing without a
        world. As many tiles as the world's share of the light asks, at least SKY_DIRECTIONS_LEAST: the
        camera's floor of 64 directions is for the soft shadows' discs (sky_directions_least), which the
        VPLs have none of, and 64 tiles took cornell-grey-world's injection from 72 to 193 ms."""
        sky = self.sky(least=SKY_DIRECTIONS_LEAST)
        if sky is None:
            return
        textures, target = sky.rsm_target(self.backend)
        with self.step(timings, sky_light.RSM_DECL):
            sky_light.rsm_tiles(self.backend, target, self._meshes[rsm.SPEC.name], self.albedo_atlas, sky.layout,
                                sky.views)
        with self.step(timings, vct_inject.SKY_DECL):
            filtered = self.vct_config.filtered_injection
            points = self.rsm_points(sky.layout.size, vct_inject.spec(filtered), vct_inject.points_per_texel(filtered))
            vct_inject.run(self.backend, self._light_target, points, textures, self.grid, self.atlas,
                           self.voxels["vox_projected"] if filtered else None)
            self._flush_light()

    def known_zero(self, product: str) -> bool:
        # The specular cones write 0 where F0 is 0, so without a glossy lobe the filter's dispatches read
        # two images instead of three.
        return product == "glossy" and not self._glossy_anywhere

    def begin_gather(self, timings: dict[str, float]) -> None:
        self.measure_support(timings)  # the pixel gather reads it (VctConfig.support_gathers)

    def gather_pixels(self, timings: dict[str, float]) -> None:
        with self.step(timings, vct_gather.PIXELS_DECL):
            gathered = (self._low or (self.indirect,))[0].size
            vct_gather.pixels(self.backend, self.pyramid, self.radiance_scale, self.gbuf, self.support,
                              self.indirect, self.ao, self.grid, self.vct_config, self.gi.seed, self._low,
                              self.sample_index, surface_support.image_samples(gathered, self.gi.sample_budget_px))
        with self.step(timings, vct_gather.GLOSSY_DECL):
            vct_gather.glossy(self.backend, self.pyramid, self.radiance_scale, self.gbuf, self._lobe_albedo,
                              self.glossy, self.grid, self.vct_config, self.camera().position_m,
                              self.gather_seed())
