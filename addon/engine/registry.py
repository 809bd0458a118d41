"""The method registry: one declaration per GI method, from which every list of methods derives.

The settings (config.py), the Blender properties and panels, the command line, the viewport, bakes, the
benchmark, the GPU timing tool and the tests all read their methods from here. Adding a method: its
module under methods/ (a class whose `spec` is its entry here), its config class if it has settings
of its own (config.GROUPS), its shaders and tests, and one `MethodSpec` below (docs/ARCHITECTURE.md,
"How to add a method").

This module imports nothing of the engine, so config.py can take its method names from it.
"""

from __future__ import annotations

import importlib
from dataclasses import dataclass

from .errors import ConfigError


@dataclass(frozen=True)
class MethodSpec:
    """What the rest of Bounce needs to know of a method without running it."""

    name: str
    summary: str
    module: str                  # under addon/engine/methods/
    class_name: str
    products: tuple[str, ...]    # the images read() returns; `albedo` with every one
    max_bounces: int             # GIConfig.bounces it computes; more are refused
    # The settings it reads, "group.field" or "group.*" (groups: config.GROUPS): the panels show these
    # alone, and `python -m addon methods` lists which methods read each setting.
    reads: tuple[str, ...]
    # Its benchmark rows: each {"group.field": value} applied to the defaults (bridge/bench.py).
    bench: tuple[dict, ...]

    @property
    def own_group(self) -> str | None:
        """The settings group of its own (its config class), or None: the first of `own_groups`."""
        return self.own_groups[0] if self.own_groups else None

    @property
    def own_groups(self) -> tuple[str, ...]:
        """Every settings group it reads besides the shared ones, in `reads` order: what its class takes
        after the gi and rsm configs (`gather` reads its own group and the probes' it gathers from)."""
        groups = [r.split(".")[0] for r in self.reads if r.split(".")[0] not in SHARED_GROUPS]
        return tuple(dict.fromkeys(groups))

    def reads_setting(self, group: str, field: str) -> bool:
        return f"{group}.{field}" in self.reads or f"{group}.*" in self.reads


SHARED_GROUPS = ("gi", "rsm")  # every method is configured through these; the others are methods' own

_IMAGE = ("gi.method", "gi.resolution")     # every method makes an image of this size
# Every method's shadow maps, and the sky's shadows at its pixels (direct light is every method's).
_LIGHT_VIEWS = ("rsm.resolution", "rsm.shadow_bias_texels", "rsm.sky_rays")

METHODS: tuple[MethodSpec, ...] = (
    MethodSpec(
        name="direct", summary="RSM-shadowed direct light only: the radiometry check against Cycles",
        module="direct", class_name="DirectMethod", products=("direct", "albedo"), max_bounces=1,
        reads=(*_IMAGE, *_LIGHT_VIEWS),
        # The sky's shadows (RsmConfig.sky_rays) by the filter and by exact rays, beside the default (auto:
        # rays where the world gives most of the light): only a world's light changes.
        bench=({"rsm.resolution": 256}, {"rsm.resolution": 512}, {"rsm.sky_rays": 0}, {"rsm.sky_rays": 8})),
    MethodSpec(
        name="rsm", summary="one bounce gathered from the shadow maps' VPLs, optionally with voxel visibility",
        module="rsm", class_name="RsmMethod", products=("direct", "indirect", "albedo"), max_bounces=1,
        reads=(*_IMAGE, "gi.seed", "gi.samples", "gi.sample_budget_px", "gi.denoise", "rsm.*"),
        # Voxel visibility marches every VPL (x6 faces for point lights): on llvmpipe 256 VPLs at 64 cells
        # is what fits a benchmark run; 1024 VPLs at 128 cells (rel_rmse_8 0.055 on cornell) takes minutes.
        bench=({"rsm.vpl_samples": 64}, {"rsm.vpl_samples": 256}, {"rsm.vpl_samples": 1024},
               {"rsm.vpl_samples": 256, "rsm.visibility": "voxel"})),
    MethodSpec(
        name="lpv", summary="light propagation volumes: VPLs propagated through an SH grid (paper 002)",
        module="lpv", class_name="LpvMethod", products=("direct", "indirect", "albedo"), max_bounces=8,
        reads=(*_IMAGE, "gi.bounces", *_LIGHT_VIEWS, "lpv.*"),
        # The published scheme as the baseline row, the improved transport at three grids, and at 32
        # without surface offsets (each cell's blocking split half and half), on one grid (no far field)
        # and with emitter classes; the octree (docs/LPV.md, "Octree"): the paper's (5 levels, k = 4, the
        # finest level with light, every level blocked), the index merge with our epsilon and blocked
        # levels at the paper's levels and k, and our defaults (time merge, 4 levels, k = 12).
        bench=({"lpv.variant": "classic", "lpv.geometry_volume": True},
               {"lpv.variant": "improved", "lpv.geometry_volume": True, "lpv.grid_cells": 16},
               {"lpv.variant": "improved", "lpv.geometry_volume": True},
               {"lpv.variant": "improved", "lpv.geometry_volume": True, "lpv.surface_offsets": False},
               {"lpv.variant": "improved", "lpv.geometry_volume": True, "lpv.far_field": False},
               {"lpv.variant": "improved", "lpv.geometry_volume": True, "lpv.emitter_classes": True},
               {"lpv.variant": "improved", "lpv.geometry_volume": True, "lpv.grid_cells": 64},
               {"lpv.variant": "octree", "lpv.octree_merge": "index", "lpv.octree_levels": 5,
                "lpv.octree_iterations": 4, "lpv.octree_epsilon": 1e-6, "lpv.octree_blocked_levels": 5},
               {"lpv.variant": "octree", "lpv.octree_merge": "index", "lpv.octree_levels": 5,
                "lpv.octree_iterations": 4},
               {"lpv.variant": "octree"})),
    MethodSpec(
        name="vct", summary="voxel cone tracing through a six-direction radiance pyramid, glossy cones",
        module="vct", class_name="VctMethod", products=("direct", "indirect", "ao", "albedo", "glossy"),
        max_bounces=8, reads=(*_IMAGE, "gi.bounces", "gi.seed", "gi.samples", "gi.sample_budget_px", "gi.denoise",
                                   *_LIGHT_VIEWS, "vct.*"),
        # Two grid sizes at the defaults (16 cones, docs/VCT.md), the half-resolution gather, and the
        # filtered injection (four points per VPL: no flicker as lights move, slower).
        bench=({"vct.voxel_cells": 64}, {"vct.voxel_cells": 64, "vct.gather_scale": 2}, {"vct.voxel_cells": 128},
               {"vct.voxel_cells": 64, "vct.filtered_injection": True})),
    MethodSpec(
        name="probes", summary="probe grid: cube-map captures re-shaded per light, L2 SH, visibility (paper 004)",
        module="probes", class_name="ProbesMethod", products=("direct", "indirect", "albedo"), max_bounces=8,
        reads=(*_IMAGE, "gi.bounces", *_LIGHT_VIEWS, "probes.*"),
        # The defaults (16 probes along the longest side, 8^2 texels a face), coarser grids (the paper's
        # 16^2 faces at 8 a side), the trilinear and back-face weights alone (no visibility), and the
        # irradiance encoding (DDGI's maps in the cube layout) beside the default SH, docs/PROBES.md.
        bench=({}, {"probes.probes_per_side": 12}, {"probes.probes_per_side": 8, "probes.face_texels": 16},
               {"probes.chebyshev_visibility": False}, {"probes.encoding": "irradiance"})),
    MethodSpec(
        name="diffusion", summary="occupancy-aware SH diffusion through the voxels, re-emitted at surfaces (paper 000)",
        module="diffusion", class_name="DiffusionMethod", products=("direct", "indirect", "albedo"), max_bounces=8,
        reads=(*_IMAGE, "gi.bounces", *_LIGHT_VIEWS, "diffusion.*"),
        # Three grids at the defaults (cone fields, two spans of steps per bounce), the single field with
        # the emitter classes (six propagations, as many as the cone fields) and without (one), and the
        # paper's transfer at 32 cells with the emitter classes, with the default steps and with its own
        # rule of one span (docs/DIFFUSION.md).
        bench=({"diffusion.grid_cells": 16}, {}, {"diffusion.grid_cells": 64},
               {"diffusion.cone_fields": False, "diffusion.emitter_class_passes": True},
               {"diffusion.cone_fields": False},
               {"diffusion.cone_fields": False, "diffusion.emitter_class_passes": True, "diffusion.transfer": "cone"},
               {"diffusion.cone_fields": False, "diffusion.emitter_class_passes": True, "diffusion.transfer": "cone",
                "diffusion.span_multiple": 1.0})),
    MethodSpec(
        name="gather", summary="distance-corrected final gather of the probes' cube maps as quad lights (paper 001)",
        module="gather", class_name="GatherMethod", products=("direct", "indirect", "albedo"), max_bounces=8,
        reads=(*_IMAGE, "gi.bounces", *_LIGHT_VIEWS, "gather.*", "probes.*"),
        # M = 2, 4, 8 quads a face side with the polygon form factor, and the paper's point-to-point
        # baseline at the default M (docs/GATHER.md).
        bench=({"gather.face_quads": 2}, {"gather.face_quads": 4}, {"gather.face_quads": 8},
               {"gather.form_factor": "point"})),
)

NAMES: tuple[str, ...] = tuple(m.name for m in METHODS)
_BY_NAME = {m.name: m for m in METHODS}


def computing(bounces: int) -> tuple[str, ...]:
    """The methods that compute `bounces` indirect bounces (GIConfig.bounces), in registry order."""
    return tuple(m.name for m in METHODS if m.max_bounces >= bounces)


def get(name: str) -> MethodSpec:
    if name not in _BY_NAME:
        raise ConfigError(f"unknown method {name!r}: known methods are {', '.join(NAMES)}")
    return _BY_NAME[name]


def method_class(name: str):
    """The method's class (its module imported on first use: passes and backends load with it)."""
    spec = get(name)
    return getattr(importlib.import_module(f"{__package__}.methods.{spec.module}"), spec.class_name)
