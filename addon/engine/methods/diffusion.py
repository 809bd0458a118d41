"""Method `diffusion`: occupancy-aware volume diffusion (Mavridis, Gaitatzes, Papaioannou; seeds 000).

Passes: those of `direct` (G-buffer, per light face: rsm, direct_light); once per geometry change the
shared voxelizer (voxelize) and diffusion_cells (each cell's plane, absorption and open faces); per RSM
face diffusion_inject (its VPLs' flux onto the sides of their cells' planes); once per update, for each
bounce, emitter class (six with DiffusionConfig.emitter_class_passes, else one) and cone field (six with
DiffusionConfig.cone_fields, cone_fields.py: the light heading through each cube face apart, else one
field of all directions): diffusion_emit (the sides' flux as Lambertian L1 SH lobes about their normals:
the injected direct light, then each bounce's absorbed flux times albedo), steps x diffusion_propagate
(gather form, ping-pong, absorbed flux accumulated per side), the class's light added to the bounce's at
every side of another class, and the bounce added to the light field (diffusion_propagate.add); with
DiffusionConfig.far_field (grids of diffusion_far_field.MIN_GRID_CELLS and more) the grid runs only its
near steps, and the light still in flight is handed to a grid of twice the cell (its own voxelizer and
cells) for the rest of the bounce, whose absorbed flux is shared back onto the fine sides
(diffusion_far_field); the gather: diffusion_lookup -> `indirect` (Cycles' Diffuse Indirect). The light
field does not depend on the camera: a camera move re-runs only the lookup.
docs/DIFFUSION.md derives the transport and measures it; diffusion_reference.py is its numpy twin.

Products: direct, indirect, albedo.
"""

from __future__ import annotations

from .. import cone_fields, registry
from ..config import DiffusionConfig
from ..grid import Grid
from ..passes import (
    declare,
    diffusion_cells,
    diffusion_far_field,
    diffusion_inject,
    diffusion_lookup,
    diffusion_propagate,
    voxelize,
    zero,
)
from ..passes.light_views import LightView
from ..passes.voxelize import Voxelizer
from .direct import OneBounceMethod


def steps_per_bounce(config: DiffusionConfig, grid: Grid, bounces: int) -> int:
    """Steps each bounce propagates: steps_per_bounce, or span_multiple x the grid's longest side (light
    moves one cell per step: the paper's rule is n bounces across Y cells in n x Y steps), all bounces
    together at most max_steps (and each at least one)."""
    per_bounce = config.steps_per_bounce or max(1, round(config.span_multiple * max(grid.dims)))
    return max(1, min(per_bounce, config.max_steps // bounces))


class FarField:
    """The far field's grid and state (diffusion_far_field): the far grid (and its shift), its own
    voxelizer and cells, two snapshots, what its surfaces absorb by the face the light came through, and
    the weights that share it onto the fine sides (per voxelization)."""

    def __init__(self, backend, far: diffusion_far_field.FarGrid, scene):
        self.far = far
        self.voxelizer = Voxelizer(backend, far.grid)
        self.voxelizer.set_scene(scene)
        self.cells = diffusion_cells.textures(backend, far.grid)
        self.snapshots = [{f"sh_{c}": backend.texture(far.grid.dims) for c in "rgb"} for _ in range(2)]
        self.absorbed = diffusion_propagate.faces(backend, far.grid)
        self.weights = None


class DiffusionMethod(OneBounceMethod):
    spec = registry.get("diffusion")
    PASSES = declare.extend(OneBounceMethod.PASSES, setup=(voxelize.DECL, diffusion_cells.DECL),
                            solve=(diffusion_inject.DECL, diffusion_inject.EMIT_DECL, diffusion_propagate.DECL,
                                   diffusion_far_field.DECL),
                            gather=(diffusion_lookup.DECL,))

    def __init__(self, backend, gi, rsm_config, diffusion_config: DiffusionConfig | None = None):
        super().__init__(backend, gi, rsm_config)
        self.diffusion_config = diffusion_config if diffusion_config is not None else DiffusionConfig()
        self.grid: Grid | None = None
        self.far: FarField | None = None

    def set_scene(self, scene) -> None:
        """Upload the scene; while the grid (fitted to the bounds) stays, the voxelizer redraws only the
        slabs the changed triangles reach (as vct's)."""
        super().set_scene(scene)
        be = self.backend
        grid = Grid.fit(*self.bounds_m, max_cells=self.diffusion_config.grid_cells)
        if grid.same_cells(self.grid):
            self.voxelizer.update(self.scene)
        else:
            self.grid = grid
            self.voxelizer = Voxelizer(be, grid)
            self.voxelizer.set_scene(self.scene)
            self.cells = diffusion_cells.textures(be, grid)
            self.atlas, self.injected, self._inject_target = diffusion_inject.atlas_target(be, grid)
            self.snapshots = [{f"sh_{c}": be.texture(grid.dims) for c in "rgb"} for _ in range(2)]
            self.absorbed = diffusion_propagate.sides(be, grid)  # one propagation's
            # One bounce's flux, every class's (but each side's own) and cone field's (the last bounce's
            # emits the next), or the propagation's itself when there is one.
            several = self.diffusion_config.emitter_class_passes or self.diffusion_config.cone_fields
            self.bounce_flux = ([diffusion_propagate.sides(be, grid) for _ in range(min(2, self.gi.bounces))]
                                if several else [self.absorbed])
            self.accumulated = diffusion_propagate.sides(be, grid) if self.gi.bounces > 1 else self.bounce_flux[0]
            self.far = None
        self.voxels = self.voxelizer.run()
        diffusion_cells.run(be, self.voxels, self.cells, self.grid)
        if self.diffusion_config.far_field and max(grid.dims) >= diffusion_far_field.MIN_GRID_CELLS:
            self._set_far_field()

    def _set_far_field(self) -> None:
        """The far grid aligned to the fine voxels (diffusion_far_field.best_shift, from the occupancy read
        back once per geometry change), rebuilt when its alignment moves, else updated as the fine one."""
        be = self.backend
        occupied = be.read(self.voxels["vox_albedo"])[..., 3] > 0
        far = diffusion_far_field.grid_for(self.grid, diffusion_far_field.best_shift(occupied))
        if self.far is not None and self.far.far.shift == far.shift:  # the same fine grid (set_scene)
            self.far.voxelizer.update(self.scene)
        else:
            self.far = FarField(be, far, self.scene)
        f = self.far
        diffusion_cells.run(be, f.voxelizer.run(), f.cells, far.grid)
        f.weights = diffusion_far_field.weights(be, f.cells, far, self.cells, self.grid, f.weights)

    def begin_solve(self, timings: dict[str, float]) -> None:
        zero.images(self.backend, list(self.injected.values()))

    def solve_view(self, view: LightView, timings: dict[str, float]) -> None:
        with self.step(timings, diffusion_inject.DECL):
            points = self.rsm_points(view.resolution, diffusion_inject.SPEC)
            diffusion_inject.run(self.backend, self._inject_target, points, self.rsm, self.grid, self.atlas,
                                 self.cells["cell_normal"])

    def finish_solve(self, timings: dict[str, float]) -> None:
        """Each bounce: per emitter class, its emitters (the injected light, then the last bounce's
        absorbed flux x albedo) and their propagation into `absorbed` (with a far field, the near steps
        and then the far grid's from the light still in flight), added to the bounce's flux at the sides of
        the other classes; the bounce added to `accumulated` (the same volumes with one bounce)."""
        be, grid, cells, far = self.backend, self.grid, self.cells, self.far
        steps = steps_per_bounce(self.diffusion_config, grid, self.gi.bounces)
        near = diffusion_far_field.near_steps(self.diffusion_config.near_steps, steps) if far else steps
        transfer = self.diffusion_config.transfer
        classes = (diffusion_inject.EMITTER_CLASSES if self.diffusion_config.emitter_class_passes
                   else (diffusion_inject.EVERY_CLASS,))
        cones = cone_fields.CONES if self.diffusion_config.cone_fields else (None,)
        propagations = [(k, cone) for k in classes for cone in cones]
        previous = None  # the last bounce's flux, which the next one re-emits
        for bounce in range(1, self.gi.bounces + 1):
            flux = self.bounce_flux[bounce % len(self.bounce_flux)]
            for k, cone in propagations:
                with self.step(timings, diffusion_inject.EMIT_DECL):
                    if previous is None:
                        diffusion_inject.emit(be, self.injected, cells, self.snapshots[0], grid, atlas=self.atlas,
                                              emitter_class=k, cone=cone)
                    else:
                        diffusion_inject.emit(be, previous, cells, self.snapshots[0], grid,
                                              vox_albedo=self.voxels["vox_albedo"], emitter_class=k, cone=cone)
                with self.step(timings, diffusion_propagate.DECL):
                    for i in range(near):
                        diffusion_propagate.run(be, self.snapshots[i % 2], self.snapshots[(i + 1) % 2], self.absorbed,
                                                cells, grid, first_step=i == 0, transfer=transfer, cone=cone)
                if far is not None:
                    with self.step(timings, diffusion_far_field.DECL):
                        self._propagate_far(self.snapshots[near % 2], steps - near, transfer, cone)
                if flux is not self.absorbed:
                    with self.step(timings, diffusion_propagate.DECL):
                        diffusion_propagate.add(be, self.absorbed, flux, grid, first=(k, cone) == propagations[0],
                                                cell_normal=cells["cell_normal"], skip_class=k)
            if self.accumulated is not flux:
                with self.step(timings, diffusion_propagate.DECL):
                    diffusion_propagate.add(be, flux, self.accumulated, grid, first=bounce == 1,
                                            cell_normal=cells["cell_normal"])
            previous = flux

    def _propagate_far(self, in_flight: dict, fine_steps_left: int, transfer: str, cone: int | None) -> None:
        """The light still in flight after the near steps, summed into the far grid, propagated there for
        as many steps as the bounce had left, and what its surfaces absorb added to the fine `absorbed`.
        A far step moves light two fine cells, but light scatters at every cell and wanders: in a closed
        white box half as many steps left 8 % of the light handed over in flight, as many 0.4 %."""
        be, f = self.backend, self.far
        diffusion_far_field.hand_over(be, in_flight, self.grid, f.snapshots, f.cells, f.far, cone)
        for i in range(max(1, fine_steps_left)):
            diffusion_propagate.run(be, f.snapshots[i % 2], f.snapshots[(i + 1) % 2], f.absorbed, f.cells,
                                    f.far.grid, first_step=i == 0, transfer=transfer, cone=cone)
        diffusion_far_field.add(be, f.absorbed, f.weights, f.far, self.absorbed, self.cells, self.grid)

    def gather_pixels(self, timings: dict[str, float]) -> None:
        with self.step(timings, diffusion_lookup.DECL):
            diffusion_lookup.run(self.backend, self.gbuf, self.cells, self.accumulated, self.indirect, self.grid)
