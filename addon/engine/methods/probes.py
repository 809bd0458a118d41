"""Method `probes`: a grid of light probes with L2 SH and distance moments (Nijasure, Pattanaik & Goel
2005, seeds 004; the visibility weighting of DDGI, Majercik et al. 2019). docs/PROBES.md.

Setup (once per geometry change, set_scene): the grid is fitted to the bounds (probe_grid.ProbeGrid.fit,
ProbesConfig.probes_per_side); probe_capture rasterizes every probe's six faces into one atlas G-buffer
(position, normal, albedo); with ProbesConfig.relocate, probe_relocate moves probes out of solids and
off near surfaces and the moved ones are captured again (probe_grid.RELOCATE_ROUNDS times); then the
distance moments of each atlas texel and which probes sit inside geometry. Solve (per light change):
with a world, probe_sky (the sky pass on the atlas, ProbesConfig.atlas_sky_directions), then per light
face probe_direct (the direct pass on the atlas), then probe_project (albedo x direct -> L2
SH per probe); each further bounce reads the field back at the atlas (probe_lookup.bounce) and
re-projects with it (GIConfig.bounces = N: N projections). Gather (per camera move, per lightmap): the
direct pass on the G-buffer, then probe_lookup -> `indirect` (Cycles' Diffuse Indirect units). The light
field (sh, moments, state, offsets) does not depend on the camera, so a camera move costs the G-buffer,
the direct light and the lookup. Products: direct, indirect, albedo.
"""

from __future__ import annotations

import numpy as np

from .. import registry
from ..config import ProbesConfig
from ..passes import copy, declare, probe_capture, probe_lookup, probe_project, probe_relocate, zero
from ..passes.light_views import LightView
from ..probe_grid import RELOCATE_ROUNDS, ProbeGrid
from .direct import OneBounceMethod, triangle_attributes


class ProbesMethod(OneBounceMethod):
    spec = registry.get("probes")
    WORLD_SUN_RSMS = False
    PASSES = declare.extend(
        OneBounceMethod.PASSES, setup=(probe_capture.CAPTURE_DECL, probe_relocate.DECL, probe_capture.MOMENTS_DECL,
                                       probe_capture.FOOTPRINT_DECL, probe_capture.LISTS_DECL),
        # The SH encoding's passes, then the irradiance encoding's (ProbesConfig.encoding picks one).
        solve=(probe_project.SKY_DECL, probe_project.SKY_COPY_DECL, probe_project.SHADE_DECL,
               probe_project.PROJECT_DECL, probe_lookup.BOUNCE_DECL, probe_project.REPROJECT_DECL,
               probe_project.CONVOLVE_DECL, probe_lookup.IRRADIANCE_BOUNCE_DECL, probe_project.RECONVOLVE_DECL),
        gather=(probe_lookup.DECL, probe_lookup.IRRADIANCE_DECL))

    def __init__(self, backend, gi, rsm_config, probes_config: ProbesConfig | None = None):
        super().__init__(backend, gi, rsm_config)
        self.probes_config = probes_config if probes_config is not None else ProbesConfig()
        self.grid: ProbeGrid | None = None
        self.probes_lit = 0  # probes captured and lit (ProbesConfig.only_read_probes)
        self.probes_moved = 0  # probes relocated off their grid positions (ProbesConfig.relocate)
        self._faces_shaded = 0  # light faces shaded into atlas_direct in the running solve

    def set_scene(self, scene) -> None:
        super().set_scene(scene)
        be, cfg = self.backend, self.probes_config
        self.grid = grid = ProbeGrid.fit(*self.bounds_m, cfg.probes_per_side, cfg.face_texels,
                                         self.scene.triangle_count, cfg.capture_mtris * 1e6)
        size = grid.atlas_size
        self.atlas = declare.allocate(be, probe_capture.ATLAS, size)
        self._atlas_target = be.target(list(self.atlas.values()), be.depth_texture(size))
        self.atlas_direct = be.texture(size)
        zero.images(be, [self.atlas_direct])  # its texels that see no geometry stay 0 (probe_project.shade)
        self.atlas_sky = None  # the sky's light on the atlas, kept between solves (begin_solve)
        self._atlas_sky_for = None  # the sky directions it was shaded with: (id, key)
        self.atlas_indirect = be.texture(size) if self.gi.bounces > 1 else None
        # Two light tables (SH, or irradiance maps): a bounce reads one while the next pass writes the other.
        self.irradiance_encoding = cfg.encoding == "irradiance"
        table = grid.tiled_size(probe_project.IRRADIANCE_TEXELS) if self.irradiance_encoding else grid.sh_size
        self._light = [be.texture(table) for _ in range(2 if self.gi.bounces > 1 else 1)]
        self.light = self._light[0]
        self.moments = be.texture(size)
        self.state = be.texture(grid.state_size)
        self.offset = probe_relocate.allocate(be, grid)
        far = probe_capture.far_m(self.bounds_m)
        # every triangle: emitters and camera-hidden objects block
        attrs = triangle_attributes(self.scene, probe_capture.SPEC, planes=self.planes)
        mesh = be.mesh(be.program(probe_capture.SPEC), attrs, "triangles") if attrs is not None else None
        tri = self.scene.positions_m
        needed = grid.read_by(tri.min(axis=1), tri.max(axis=1), cfg.normal_bias * grid.spacing_m) \
            if cfg.only_read_probes else None
        self.probes_lit = grid.count if needed is None else int(needed.sum())
        probe_capture.run(be, self._atlas_target, self.atlas, mesh, grid, probe_capture.face_matrices(grid, far),
                          needed)
        self.probes_moved = self.relocate(mesh, far) if cfg.relocate else 0
        probe_capture.moments(be, self.atlas, self.moments, self.state, grid, cfg.backface_share, self.offset,
                              needed)
        self.footprint = probe_capture.footprint(be, self.atlas, self.offset, grid) if cfg.area_samples > 1 else None
        self.texel_lists = probe_capture.texel_lists(be, self.atlas, self.footprint)

    def relocate(self, mesh, far: float) -> int:
        """Move probes out of solids and off near surfaces (probe_relocate), capturing the moved ones
        again after each of RELOCATE_ROUNDS steps; returns how many probes end off their grid position.
        A step needs the capture from the positions the previous one chose, hence one capture per step;
        the probes a step leaves alone keep theirs."""
        be, grid = self.backend, self.grid
        for _ in range(RELOCATE_ROUNDS):
            offsets_m, moved = probe_relocate.step(be, self.atlas, self.offset, grid, self.bounds_m)
            if not moved.any():
                break
            probe_relocate.clear_moved(be, self.atlas, self.offset, grid)
            positions_m = grid.positions_m() + offsets_m
            probe_capture.draw(be, self._atlas_target, mesh, grid, probe_capture.face_matrices(grid, far, positions_m),
                               moved, positions_m)
        return int(np.count_nonzero(np.any(offsets_m != 0.0, axis=1)))

    def offsets_m(self) -> np.ndarray:
        """(count, 3) each probe's move off its grid position (m), in probe order (0 without relocation)."""
        return self.backend.read(self.offset).reshape(-1, 4)[:, :3].astype(np.float64)

    def work(self) -> dict[str, int]:
        """The probes the grid has, those captured and lit (the rest no lookup reads), and those relocated."""
        return {"probes": self.grid.count if self.grid else 0, "probes_lit": self.probes_lit,
                "probes_moved": self.probes_moved}

    def field(self) -> dict:
        """The light field the lookup reads."""
        return {"irradiance" if self.irradiance_encoding else "sh": self.light, "moments": self.moments,
                "state": self.state, "probe_offset": self.offset}

    def begin_solve(self, timings: dict[str, float]) -> None:
        # No zeroing pass over the atlas (1.57 M texels on cornell, ~27 ms on llvmpipe): the first face
        # replaces the last solve's light; the sky, when there is one, is that first face. Its light on
        # the atlas changes only with the geometry (set_scene) or the sky's directions, not when a lamp
        # moves, so it is shaded into `atlas_sky` once and copied in (window-sky-sun at 128 px: the sky
        # pass on the atlas took 380-415 ms of the 760 ms a lamp's move cost, the copy 11-13 ms).
        self._faces_shaded = 0
        sky = self.sky(self.probes_config.atlas_sky_directions)
        if sky is None:
            return
        if self._atlas_sky_for != (id(sky), sky.key):
            if self.atlas_sky is None:
                self.atlas_sky = self.backend.texture(self.atlas_direct.size)
                zero.images(self.backend, [self.atlas_sky])  # texels that see no geometry stay 0
            self.shade_sky(timings, probe_project.SKY_DECL, self.atlas["position"], self.atlas["normal"],
                           self.atlas_sky, accumulate=False, most=self.probes_config.atlas_sky_directions,
                           texel_lists=tuple(self.texel_lists.values()), rays=False)
            self._atlas_sky_for = (id(sky), sky.key)
        with self.step(timings, probe_project.SKY_COPY_DECL):
            copy.run(self.backend, self.atlas_sky, self.atlas_direct)
        self._faces_shaded = 1

    def forget_kept_light(self) -> None:
        super().forget_kept_light()
        self._atlas_sky_for = None  # the sky's light on the atlas (begin_solve)

    def skies(self) -> list:
        """The camera's sky directions and the atlas's (ProbesConfig.atlas_sky_directions)."""
        skies = super().skies()
        atlas_sky = self.sky(self.probes_config.atlas_sky_directions)
        if atlas_sky is not None and not any(atlas_sky is sky for sky in skies):  # the same directions: one draw
            skies.append(atlas_sky)
        return skies

    def solve_view(self, view: LightView, timings: dict[str, float]) -> None:
        with self.step(timings, probe_project.SHADE_DECL):
            shadow, shadow_view = self.shadow_map(view)
            probe_project.shade(self.backend, self.atlas, self.atlas_direct, shadow, shadow_view,
                                self.rsm_config.shadow_bias_texels, self.emitters, self._faces_shaded == 0,
                                self.texel_lists, self.footprint, self.probes_config.area_samples)
        self._faces_shaded += 1

    def finish_solve(self, timings: dict[str, float]) -> None:
        self.finish_direct()
        self.encode_bounces(timings, self.gi.bounces)

    def finish_direct(self) -> None:
        """A solve with no light face replaced none of the last solve's direct light: zeroed here."""
        if self._faces_shaded == 0:
            zero.images(self.backend, [self.atlas_direct])

    def _encoding(self) -> tuple:
        """(first bounce's pass, later bounces' pass, the bounce lookup, the encoding's function)."""
        if self.irradiance_encoding:
            return (probe_project.CONVOLVE_DECL, probe_project.RECONVOLVE_DECL,
                    probe_lookup.IRRADIANCE_BOUNCE_DECL, probe_project.convolve)
        return (probe_project.PROJECT_DECL, probe_project.REPROJECT_DECL, probe_lookup.BOUNCE_DECL,
                probe_project.run)

    def encode_bounces(self, timings: dict[str, float], count: int) -> None:
        """`self.light` := bounces 1..count of the probe field: `count` encodings, each after the first
        preceded by the field read back at the atlas (`read_back`)."""
        first, later, _, encode = self._encoding()
        self.light = self._light[0]
        with self.step(timings, first):
            encode(self.backend, self.atlas, self.atlas_direct, self.light, self.grid)
        for bounce in range(2, count + 1):
            self.read_back(timings)
            self.light = self._light[(bounce - 1) % 2]
            with self.step(timings, later):
                encode(self.backend, self.atlas, self.atlas_direct, self.light, self.grid, self.atlas_indirect)

    def read_back(self, timings: dict[str, float]) -> None:
        """`atlas_indirect` := the probe field (`self.light`) read at every atlas texel: the indirect light
        at the surfaces the probes see, which the next bounce re-emits."""
        with self.step(timings, self._encoding()[2]):
            probe_lookup.run(self.backend, self.atlas["position"], self.atlas["normal"], self.field(),
                             self.atlas_indirect, self.grid, self.probes_config)

    def gather_pixels(self, timings: dict[str, float]) -> None:
        with self.step(timings, probe_lookup.DECL):
            probe_lookup.run(self.backend, self.gbuf["position"], self.gbuf["normal"], self.field(), self.indirect,
                             self.grid, self.probes_config)
