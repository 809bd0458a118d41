"""Diffusion far field: light beyond the fine grid's near steps carried on a grid of twice the cell size
(docs/DIFFUSION.md, "Far field"; the scheme of lpv_far_field, for absorbed flux instead of accumulated SH).

A bounce's light needs twice the grid's span of steps to settle (DiffusionConfig.span_multiple). Here the
fine grid runs only its first `near_steps` K, and a coarse grid (lpv_far_field.grid_for: same origin, cell
2h; its own voxelization and cells) the whole span, in half as many steps at 1/8 of the cells. Both count
what their surfaces absorb by time of flight (lpv_far_field.fine_weight / coarse_weight, the
`weight` of diffusion_propagate.run): light absorbed at fine time t is counted w(t) on the fine grid and
1 - w(t) on the coarse one, so once in sum. Absorbed light leaves the flight, so weighting the count does
not change the transport of either grid.

`source`: the fine grid's emitted flux per side (the injection atlas, or a bounce's absorbed flux times
the fine albedo) -> the coarse grid's, summed over each coarse cell's 2 x 2 x 2 fine cells, a side to the
coarse side its normal agrees with (far_field_source.comp.glsl); the coarse grid then emits it as its own
(diffusion_inject.emit from volumes) per emitter class. `add`: the coarse grid's absorbed flux shared out
to the fine sides by receiving area, never more irradiance than the coarse side's and never more flux
than it absorbed, added to the fine grid's absorbed flux (far_field_add.comp.glsl); everything
downstream (the class and bounce sums, the next bounce's emitters, the lookup) reads the sum.
Twins: diffusion_reference.far_source / far_add.
"""

from __future__ import annotations

from ..backends.base import Backend, Image, Sampler, ShaderSpec, Var, group_count
from ..grid import Grid
from .declare import VOX_ALBEDO, PassDecl
from .diffusion_cells import CELL_BLOCK, CELL_NORMAL
from .diffusion_inject import INJECTED
from .diffusion_propagate import ABSORBED

# The fine grid's longest side from which the far field runs: its 16-cell coarse grid is the coarsest
# that resolves a room (one 16-cell grid: window-room rel_rmse_8 1.160 against 0.366 at 32, docs/DIFFUSION.md).
MIN_GRID_CELLS = 32


def _source_spec(atlas: bool) -> ShaderSpec:
    dim = "2D" if atlas else "3D"
    return ShaderSpec(
        name="diffusion_far_field_source" + ("_atlas" if atlas else "_albedo"),
        compute="diffusion/far_field_source.comp.glsl",
        local_size=(4, 4, 4),
        samplers=(Sampler("flux_plus", dim), Sampler("flux_minus", dim), Sampler("cell_normal", "3D"),
                  Sampler("cell_block", "3D"), Sampler("coarse_normal", "3D"))
        + (() if atlas else (Sampler("vox_albedo", "3D"),)),
        images=(Image("coarse_plus", "3D", "RGBA32F", "write"), Image("coarse_minus", "3D", "RGBA32F", "write")),
        uniforms=(Var("dims", "ivec3"), Var("coarse_dims", "ivec3")) + ((Var("tiles_x", "int"),) if atlas else ()),
        defines=(("ATLAS", "1"),) if atlas else (),
    )


SOURCE_SPECS = {atlas: _source_spec(atlas) for atlas in (True, False)}

ADD = ShaderSpec(
    name="diffusion_far_field_add",
    compute="diffusion/far_field_add.comp.glsl",
    local_size=(4, 4, 4),
    samplers=(Sampler("far_plus", "3D"), Sampler("far_minus", "3D"), Sampler("coarse_normal", "3D"),
              Sampler("cell_normal", "3D"), Sampler("cell_block", "3D")),
    images=(Image("acc_plus", "3D", "RGBA32F", "read_write"), Image("acc_minus", "3D", "RGBA32F", "read_write")),
    uniforms=(Var("dims", "ivec3"),),
)

DECL = PassDecl("diffusion_far_field", "solve", (INJECTED, ABSORBED, CELL_NORMAL, CELL_BLOCK, VOX_ALBEDO),
                (ABSORBED,), "light beyond the near steps carried on a grid of twice the cell (its emitters "
                "summed from the fine grid's, its absorbed flux shared back)")


def near_steps(configured: int, grid: Grid, steps: int) -> int:
    """The fine grid's steps K with a far field: `configured`, or (0) the grid's longest side, at most the
    bounce's own `steps`."""
    return max(1, min(configured or max(grid.dims), steps))


def source(backend: Backend, flux: dict, cells: dict, fine: Grid, coarse_flux: dict, coarse_cells: dict,
           coarse: Grid, atlas=None, vox_albedo=None) -> None:
    """coarse_flux (flux_plus / flux_minus, W, every coarse cell written) := the fine grid's emitted flux
    per side summed into its coarse cells: `flux` the injection atlases (`atlas` given) or volumes of
    absorbed flux times the fine `vox_albedo`."""
    spec = SOURCE_SPECS[atlas is not None]
    uniforms = {"dims": fine.dims, "coarse_dims": coarse.dims}
    samplers = {"flux_plus": flux["flux_plus"], "flux_minus": flux["flux_minus"], **cells,
                "coarse_normal": coarse_cells["cell_normal"]}
    if atlas is not None:
        uniforms["tiles_x"] = atlas.tiles_x
    else:
        samplers["vox_albedo"] = vox_albedo
    backend.dispatch(backend.program(spec), group_count(coarse.dims, spec.local_size), uniforms=uniforms,
                     samplers=samplers,
                     images={"coarse_plus": coarse_flux["flux_plus"], "coarse_minus": coarse_flux["flux_minus"]})


def add(backend: Backend, coarse_absorbed: dict, coarse_cells: dict, absorbed: dict, cells: dict, fine: Grid) -> None:
    """absorbed (the fine grid's flux_plus / flux_minus, W) += the coarse grid's absorbed flux shared out
    to the fine sides (far_field_add.comp.glsl)."""
    backend.dispatch(backend.program(ADD), group_count(fine.dims, ADD.local_size), uniforms={"dims": fine.dims},
                     samplers={"far_plus": coarse_absorbed["flux_plus"], "far_minus": coarse_absorbed["flux_minus"],
                               "coarse_normal": coarse_cells["cell_normal"], **cells},
                     images={"acc_plus": absorbed["flux_plus"], "acc_minus": absorbed["flux_minus"]})
