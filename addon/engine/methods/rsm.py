"""Method `rsm`: direct light plus one indirect bounce gathered from the RSMs' VPLs, no visibility
(Dachsbacher & Stamminger 2005). The yardstick the propagation methods must beat: ../shared/BASELINE.md
measured this gather at rel_rmse_8 0.215, bias 1.15 on the Cornell box (occlusion is missing, so it is
too bright), 0.035 with exact visibility.

Passes: those of `direct`, then per RSM face: rsm_gather (a gather: it reads each face's kept RSM, so a
camera move redraws no RSM). With `RsmConfig.visibility = "voxel"` the
scene is voxelized once per geometry change (passes/voxelize.py) and every VPL's visibility is marched
through the occupancy grid. Products: direct, indirect, albedo.
"""

from __future__ import annotations

from .. import registry
from ..grid import Grid
from ..passes import accumulate, declare, denoise, rsm_gather, surface_support, voxel_view, voxelize
from ..passes.light_views import LightView
from ..passes.voxelize import Voxelizer
from .direct import OneBounceMethod


class RsmMethod(OneBounceMethod):
    spec = registry.get("rsm")
    PASSES = declare.extend(OneBounceMethod.PASSES, setup=(voxelize.DECL,),
                            gather=(surface_support.DECL, rsm_gather.DECL, accumulate.DECL, denoise.DECL))
    NOISY = ("indirect",)
    # rsm_gather.block_pdf's scratch, made on the first gather, and each face's block_pdf by (light,
    # face): computed on an update's gather and kept through the refinement gathers that follow, which
    # keep the G-buffer and the RSMs it is made from.
    block_importance: dict | None = None
    block_pdfs: dict | None = None

    def set_scene(self, scene) -> None:
        super().set_scene(scene)
        self.voxels = None
        if self.rsm_config.visibility == "voxel":
            self.voxelize()

    def voxelize(self) -> dict:
        """Voxelize the uploaded geometry (once per set_scene): the occupancy for visibility."""
        if self.voxels is None:
            local = self.scene  # re-centred by DirectMethod.set_scene, like every pass's input
            self.grid = Grid.fit(*local.bounds_m(), max_cells=self.rsm_config.voxel_cells)
            self.voxelizer = Voxelizer(self.backend, self.grid)
            self.voxelizer.set_scene(local)
            self.voxels = self.voxelizer.run()
        return self.voxels

    def voxel_view(self):
        """The debug view of the voxel grid at the current G-buffer (a texture; see passes/voxel_view)."""
        voxels = self.voxelize()
        if getattr(self, "_voxel_view", None) is None or self._voxel_view.size != self.direct.size:
            self._voxel_view = self.backend.texture(self.direct.size)
        voxel_view.run(self.backend, self.gbuf["position"], voxels["vox_albedo"], self.grid, self._voxel_view)
        return self._voxel_view

    def begin_gather(self, timings: dict[str, float]) -> None:
        self.measure_support(timings)  # every face's gather reads it (RsmConfig.support_draws)

    def gather_view(self, view: LightView, timings: dict[str, float]) -> None:
        with self.step(timings, rsm_gather.DECL):
            share = self.vpl_shares.get(view.light_index)
            vpls = self.rsm_config.vpl_samples if share is None else max(1, round(self.rsm_config.vpl_samples * share))
            if self.block_importance is None:
                self.block_importance = rsm_gather.importance_textures(self.backend, self.rsm_config.vpl_samples)
                self.block_pdfs = {}
            face = (view.light_index, view.face_index)
            if face not in self.block_pdfs:
                self.block_pdfs[face] = rsm_gather.pdf_texture(self.backend, self.rsm_config.vpl_samples)
            if self.sample_index == 0:
                rsm_gather.block_pdf(self.backend, self.gbuf, self.rsm, self.block_importance, vpls,
                                     self.block_pdfs[face])
            rsm_gather.run(self.backend, self.gbuf, self.rsm, self.indirect, vpls,
                           self.gi.seed + view.light_index * 6 + max(view.face_index, 0), view.view_projection,
                           self.block_pdfs[face], self.support,
                           occupancy=self.voxels["vox_albedo"] if self.voxels else None,
                           grid=self.voxels and self.grid, offset_cells=self.rsm_config.voxel_offset_cells,
                           sample=self.sample_index, draw_sets=self.rsm_config.support_draws,
                           image_sets=surface_support.image_samples(self.indirect.size, self.gi.sample_budget_px))
