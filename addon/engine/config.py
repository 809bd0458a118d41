"""Frozen, validated configuration dataclasses.

Every field declares its allowed range (or choices) in its metadata; `__post_init__` checks them and
raises `ConfigError` naming the field and the range. Blender properties mirror these fields (same
names, defaults and limits); a test keeps the two in step.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
from typing import Any

from . import registry
from .errors import ConfigError

METHODS = registry.NAMES


def _num(default, lo, hi, doc):
    return field(default=default, metadata={"min": lo, "max": hi, "doc": doc})


def _choice(default, choices, doc):
    return field(default=default, metadata={"choices": tuple(choices), "doc": doc})


class _Validated:
    """Mixin: range/choice validation from field metadata, and construction from a dict."""

    def __post_init__(self) -> None:
        for f in dataclasses.fields(self):
            value = getattr(self, f.name)
            meta = f.metadata
            where = f"{type(self).__name__}.{f.name}"
            if "choices" in meta:
                if value not in meta["choices"]:
                    raise ConfigError(f"{where} = {value!r}: must be one of {', '.join(meta['choices'])}")
            elif "min" in meta:
                expected = type(f.default)
                if isinstance(value, bool) or not isinstance(value, (int, float)):
                    raise ConfigError(f"{where} = {value!r}: must be a number in [{meta['min']}, {meta['max']}]")
                if expected is int and not float(value).is_integer():
                    raise ConfigError(f"{where} = {value!r}: must be an integer in [{meta['min']}, {meta['max']}]")
                if not (meta["min"] <= value <= meta["max"]):  # also rejects NaN
                    raise ConfigError(f"{where} = {value!r}: out of range [{meta['min']}, {meta['max']}]")
                object.__setattr__(self, f.name, expected(value))
            elif isinstance(f.default, bool) and not isinstance(value, bool):
                raise ConfigError(f"{where} = {value!r}: must be True or False")

    @classmethod
    def from_dict(cls, values: dict[str, Any]):
        names = {f.name for f in dataclasses.fields(cls)}
        unknown = sorted(set(values) - names)
        if unknown:
            known = ", ".join(sorted(names))
            raise ConfigError(f"{cls.__name__}: unknown field(s) {', '.join(unknown)}; known: {known}")
        return cls(**values)

    def to_dict(self) -> dict[str, Any]:
        return dataclasses.asdict(self)


@dataclass(frozen=True)
class RsmConfig(_Validated):
    """Reflective shadow maps: one per light (six faces for a point light)."""

    # A perspective view gets fewer where its footprint is narrower than the scene's diagonal, at the
    # same texel width (light_views.view_texels): a lamp's face that sees the ceiling a few centimetres
    # away is drawn at 64.
    resolution: int = _num(256, 16, 4096, "most texels a side of an RSM view (per face for point lights; a "
                                          "face that sees only nearby geometry gets fewer, as wide)")
    vpl_samples: int = _num(256, 1, 4096, "VPLs gathered per pixel by the `rsm` method")
    shadow_bias_texels: float = _num(0.0, 0.0, 8.0, "shadow bias in RSM texels beyond the 1.5-texel normal offset")
    visibility: str = _choice("none", ("none", "voxel"), "VPL visibility in the `rsm` gather: none or voxel-traced")
    voxel_cells: int = _num(64, 8, 512, "voxel grid cells along the scene's longest side (voxel visibility)")
    voxel_offset_cells: float = _num(1.5, 0.0, 4.0, "ray ends moved off their surfaces, in cells")
    # Where the denoise filter finds little of a pixel's own surface around it, the `rsm` gather makes
    # this many sets of VPL draws (passes/surface_support.py; docs/RSM.md). Sponza (noise between seeds,
    # one update) at 128 / 512 px: 1 set 0.099 / 0.045, 2 sets 0.071 / 0.031, 3 sets 0.059 / 0.026 (4:
    # 0.052 at 128 px, and with --accumulate 16 0.0108 as 3); a lights update 1.14x two sets' on Sponza
    # at 128 px, 1.11x on cornell, whose noise it leaves alone.
    support_draws: int = _num(3, 1, 4, "sets of VPL draws at pixels whose denoise filter finds little of their "
                                       "surface around them (thin or small details; 1: one set everywhere)")
    # An area light is split into patches_per_side^2 patches (sectors for disks and ellipses), each
    # with its exact unshadowed irradiance and soft shadows from its own RSM faces, which it costs
    # (area_light.py, docs/DIRECT.md).
    area_patches: int = _num(2, 1, 8, "patches per side an area light is split into, each with its own soft shadows")
    # The world's bounce: this many suns, each a region of the sky with its exact vector irradiance
    # (world.py) and its own RSM face (the VPLs of rsm, lpv and diffusion; vct and probes take the sky
    # pass's directions instead): 16 kept Sponza's update near 0.7 s on llvmpipe (32: 1.4 s); 0 leaves
    # the world out (no direct light from it either).
    world_suns: int = _num(16, 0, 256, "suns the world's bounce is split into for rsm, lpv and diffusion (0: the "
                           "world lights no method)")
    # A sun's RSM spans the whole scene, so at `resolution` its texels are coarse where the camera looks
    # closely: a window's sunlit patch came out a camera pixel off along one edge (window-room, direct
    # rel_rmse_8 0.298 at 256 texels). Its direct light reads a shadow map of its own at this size
    # (docs/DIRECT.md); its VPLs still come from the RSM.
    sun_shadow_texels: int = _num(1024, 0, 8192, "texels per side of a sun's own shadow map for its direct "
                                  "light (0: its RSM's)")
    # The world's direct light: at most this many regions of the sky (the same importance-stratified
    # split, finer), each shadowed by a sky_texels^2 tile of one atlas and all evaluated in one pass over
    # the G-buffer (passes/sky_light.py). The count is this times the world's share of the scene's
    # direct light (world.sky_direction_count), at least a quarter of it within a budget of shadow draws
    # (direct.sky_directions_least): a sky lighting a room through its window gets most of them, a dim
    # world beside a sun few (docs/DIRECT.md).
    sky_directions: int = _num(256, 1, 1024, "most regions of the sky its direct light is split into, one pass "
                               "for all (fewer when the world gives less of the light)")
    sky_texels: int = _num(64, 16, 1024, "shadow map side in texels of each sky direction (at most what keeps "
                                         "their atlas 2048 texels a side)")
    # The sky's shadows at the camera's pixels (and a bake's texels): with this many rays per region,
    # each tested exactly against the triangles (bvh.py), in place of the shadow maps' soft-shadow
    # filter. Window-sky's direct light 0.073 -> 0.028 at 8, the sky pass 19-200x dearer on llvmpipe
    # (docs/DIRECT.md, "Exact rays"). -1 (auto, the default): 8 where the world gives at least 30 % of
    # the direct light (3 % in bakes), else the filter (sky_light.rays_for); the viewport takes the filter.
    sky_rays: int = _num(-1, -1, 16, "rays per sky region tested exactly against the triangles for the sky's "
                                     "shadows (0: the shadow maps' filter, fast; -1: auto, 8 where the world "
                                     "gives at least 30 % of the direct light in renders, 3 % in bakes)")


@dataclass(frozen=True)
class LpvConfig(_Validated):
    """Light propagation volume (method `lpv`): docs/LPV.md derives the units and the variants."""

    grid_cells: int = _num(32, 8, 256, "LPV cells along the scene's longest side")
    iterations: int = _num(16, 1, 256, "propagation steps (classic); improved runs at least the grid's Manhattan span "
                           "(with a far field: near_steps on the grid, the span on the far field's)")
    # Defaults: the improved transport with occlusion (Cornell rel_rmse_8 0.42); the published scheme
    # stays a variant for comparison (1.15, no better than a constant: ../shared/BASELINE.md).
    variant: str = _choice("improved", ("classic", "improved", "octree"),
                           "transport: classic CLPV 5-face scheme, improved (straight, flux-conserving), or "
                           "octree (improved on a mip chain of grids, merged: paper 002)")
    geometry_volume: bool = field(default=True, metadata={"doc": "occlude propagation by the voxelized surfaces"})
    # On: a surface blocks the transfers on its side of the cell's centre (by where it lies in the cell),
    # so light does not depend on how walls align with cells (thin-wall rel_rmse_8 0.22, 0.68 off); off:
    # each cell's blocking is split half and half between entering and leaving (docs/LPV.md).
    # The improved variant's; classic, the published baseline, always splits half and half.
    surface_offsets: bool = field(default=True, metadata={
        "doc": "geometry volume: a surface blocks the transfers on its side of the cell's centre"})
    # On: the grid runs only its near steps and a grid of twice the cell carries the light further
    # (docs/LPV.md, "Far field": Cornell rel_rmse_8 0.38, 0.54 on one grid, at 32 cells, 4x fewer fine
    # steps). Improved variant, grid_cells >= 32, on the coarsest grid (the only one without cascades).
    far_field: bool = field(default=True, metadata={
        "doc": "carry light beyond the near steps on a grid of twice the cell size (faster, less on-axis excess)"})
    near_steps: int = _num(0, 0, 256, "far field: steps the fine grid runs (0: half of grid_cells)")
    # On: the VPLs are propagated in six sets by their normal's dominant signed axis, and a surface reads
    # every set but its own: a surface cannot light another facing its way, but in L1 SH the strong light
    # leaving a lit floor cancels the weak light arriving at it (docs/LPV.md, "Emitter classes": lower
    # error on every scene but emissive, e.g. cornell rel_rmse_8 0.338 (0.385 without), thin-wall 0.151
    # (0.280)). Off by default: six propagations instead of one (7x the propagation time on llvmpipe).
    # The improved variant with one cascade, first bounce.
    emitter_classes: bool = field(default=False, metadata={
        "doc": "a surface reads no light from surfaces facing its way (six propagations; one cascade)"})
    # Octree (variant octree, passes/lpv_octree.py): the grid is level 0 of a mip chain of grids, each
    # twice the cell of the one below, each propagated octree_iterations steps and merged coarse to fine.
    # The paper's settings: 5 levels (32^3 .. 2^3), k = 4, the index merge with epsilon ~0 (the finest
    # level with non-zero light), every level blocked. Ours: the time merge, which splits the light
    # between the levels by its time of flight as the far field does, 4 levels (32^3 .. 4^3), k = 12:
    # the least error of the settings measured on cornell, window-room and thin-wall (docs/LPV.md,
    # "Octree", measures both).
    octree_levels: int = _num(4, 2, 6, "octree: grids in the mip chain, each twice the cell of the one below")
    octree_iterations: int = _num(12, 1, 64, "octree: propagation steps on every level (the paper's k = 4)")
    octree_merge: str = _choice("time", ("index", "time"), "octree: levels merged per cell by the finest holding "
                                "light (index, the paper's) or per time of flight (time)")
    octree_epsilon: float = _num(0.5, 1e-6, 1.0, "octree, index merge: a finer level counts where its light reaches "
                                 "this share of the coarser answer's, fully at twice it (~0: the paper's rule)")
    # A cell of 8 grid cells or more holds walls and the open space in front of them together: its
    # geometry volume blocks the light of the surfaces in it (cornell, index merge: bias 0.70 with four
    # blocked levels, 0.90 with three; docs/LPV.md, "Octree").
    octree_blocked_levels: int = _num(3, 0, 6, "octree: the finest levels the geometry volume blocks (coarser ones "
                                      "propagate unblocked)")
    cascades: int = _num(1, 1, 4, "nested grids, each finer one half the cell size, the finest around the camera")
    cell_size_m: float = _num(0.0, 0.0, 1.0e6, "finest cascade's cell in metres when the cascades can cover "
                              "the scene with it; 0: the coarsest fits the scene")


@dataclass(frozen=True)
class VctConfig(_Validated):
    """Voxel cone tracing (method `vct`): docs/VCT.md derives the units and measures the settings."""

    voxel_cells: int = _num(64, 8, 256, "voxel grid cells along the scene's longest side")
    diffuse_cones: int = _num(16, 3, 32, "cones per gather point, each 1 / n of the cosine-weighted hemisphere")
    bounce_cones: int = _num(6, 3, 32, "cones per voxel side for bounces after the first (smoother light)")
    step_ratio: float = _num(1.0, 0.1, 2.0, "march step as a fraction of the sampled voxel's size")
    offset_cells: float = _num(1.5, 0.0, 4.0, "cone origins moved off their surface along the normal, in cells")
    gather_scale: int = _num(1, 1, 4, "cones at one pixel per n x n block, upsampled along edges (1: every pixel)")
    # Where the denoise filter finds little of a pixel's own surface around it (thin columns, leaves, the
    # last pixels before an edge) it cannot average the gather's noise, so those pixels gather this many
    # times the image's gathers (gather.comp.glsl; 3, 8 or 16 gathers trace one spiral of cones). With one
    # gather per pixel, Sponza 128 / 512 px: noise between seeds 0.118 / 0.058 -> 0.083 / 0.037 at 2 (4:
    # 0.072 at 128; 3: 0.035 at 512), for 18 % more gather half on llvmpipe; cornell unchanged (docs/VCT.md).
    support_gathers: int = _num(2, 1, 4, "gathers at pixels whose denoise filter finds little of their surface around "
                                         "them (thin or small details; 1: one gather everywhere)")
    radiance: str = _choice("anisotropic", ("anisotropic", "isotropic"),
                            "voxel radiance: six directions, or their mean (directional opacity kept)")
    specular_cones: int = _num(8, 1, 32, "cones sampling each glossy lobe (GGX, importance sampled)")
    specular_aperture: float = _num(1.0, 0.25, 4.0, "each specular cone's solid angle, x its share of the lobe")
    specular_side_cap: float = _num(0.05, 0.02, 1.0, "specular cone's sampled voxel side at most this x distance")
    # On: a VPL is shared bilinearly between the 2 x 2 cells nearest it along its surface (those holding
    # geometry facing its normal's axis), so its flux moves continuously as a light moves: a light moving
    # 1 mm per frame flickers by 1.1 % per frame with one cell per VPL, 0.3 % filtered (docs/VCT.md,
    # "Filtered injection"). Off by default: four point splats per VPL instead of one made the injection
    # 3-6x slower on llvmpipe (the VCT update up to 2.4x), for no accuracy.
    filtered_injection: bool = field(default=False, metadata={
        "doc": "share each VPL between the 2 x 2 nearest cells along its surface (no flicker as lights move)"})


@dataclass(frozen=True)
class ProbesConfig(_Validated):
    """Probe grid with L2 SH and distance moments (method `probes`, paper 004): docs/PROBES.md."""

    # Cornell at 128 px against Cycles (docs/PROBES.md), rel_rmse_8: 4 probes a side 0.35, 8 0.20,
    # 12 0.16, 16 0.124 at 8^2 texels a face; at 16 a side 4^2 faces 0.22, 6^2 0.17 (the visibility
    # moments' resolution). Cost: 6 draws of the scene per probe per geometry change, 6 face_texels^2
    # texels per probe re-shaded per light change. Other face sizes do not converge: each texel is shaded
    # at its centre, so a bright feature seen at a grazing angle is hit or missed by where the rows fall
    # (docs/PROBES.md, "The capture aliases bright light seen at a grazing angle").
    probes_per_side: int = _num(16, 2, 64, "probes along the bounds' longest side (spacing = that side / n)")
    face_texels: int = _num(8, 4, 64, "texels per side of each of a probe's six captured faces")
    # A face texel that sees its surface at a grazing angle (|n . w| < 0.25) is shaded at this many
    # points along its footprint instead of its centre alone (direct/shade.comp.glsl, texel_area_light):
    # the capture's aliasing of bright light seen edge-on. 1: the centre only. 4: 12 of 13 procedural
    # scenes read better than at the centres, window-room at two bounces 0.19 against 0.25, and within
    # 0.01 of 8 on 12 (docs/PROBES.md, "Area sampling of grazing texels"), for a light update 1.05-1.1x
    # the centres' (the grazing texels share the centre's soft-shadow taps).
    area_samples: int = _num(4, 1, 16, "points a grazing probe texel is shaded at along its footprint (1: its "
                             "centre)")
    normal_bias: float = _num(0.25, 0.0, 1.0, "lookup point moved off its surface along the normal, x spacing")
    # sh: the paper's nine coefficients per colour; irradiance: a cube map of exact clamped-cosine
    # irradiance per probe (DDGI's irradiance map, in the capture's cube layout), no SH ringing: Cornell
    # rel_rmse_8 0.101 against 0.124, but its convolution made the solve ~6x slower (docs/PROBES.md).
    encoding: str = _choice("sh", ("sh", "irradiance"), "probe light: L2 SH (the paper's) or an irradiance "
                            "cube map per probe (exact cosine convolution)")
    # The world's direct light on the surfaces the probes see: the camera's sky pass (docs/DIRECT.md) over
    # the atlas, with its own count of directions since the atlas holds ~40x a 128 px image's pixels and
    # a probe's integral over its sphere blurs what fewer directions leave. window-sky, probes indirect
    # rel_rmse_8 against 2048 spp: 0.267 / 0.154 / 0.152 at 32 / 64 / 186 directions, the pass 0.43 /
    # 0.89 / 4.75 s on llvmpipe (docs/PROBES.md).
    atlas_sky_directions: int = _num(64, 1, 1024, "most regions of the sky that light the surfaces the probes "
                                     "see (the camera's are rsm.sky_directions)")
    chebyshev_visibility: bool = field(default=True, metadata={
        "doc": "weigh probes by Chebyshev visibility from their distance moments (no light through walls)"})
    # The capture draws the whole scene 6 times per probe: 1e6 triangles at 16 a side (256 probes on a
    # flat floor) took 308 s on llvmpipe (tests/hard, million-triangle floor). Above this budget
    # probes_per_side is lowered until 6 x probes x triangles fits (probe_grid.ProbeGrid.fit).
    capture_mtris: float = _num(50.0, 1.0, 1.0e6, "most triangles drawn per capture, in millions (6 x probes x "
                                "triangles): fewer probes where a scene has more")
    # A probe inside a closed object or buried in a wall sees back faces in most directions: its light
    # is the inside's, so it is switched off (1: never).
    backface_share: float = _num(1.0, 0.0, 1.0, "probe switched off when back faces fill more than this "
                                 "share of its sphere")
    # Only the probes some lookup reads (the corners of cells within the normal bias of a triangle,
    # probe_grid.ProbeGrid.read_by) are captured and lit; the images are the same (tested), and the
    # others are off. Cornell at 16 a side: 2872 of 4096 probes (docs/PROBES.md). A volume for
    # engines (`bake --target probes`) wants every probe: dynamic objects move through empty space.
    only_read_probes: bool = field(default=True, metadata={
        "doc": "capture and light only the probes a surface's lookup reads (off: every probe)"})
    # DDGI's relocation, this rule (probe_grid.relocation_step, docs/PROBES.md "Relocation"): a probe
    # inside a solid moves out through a back face into the bounds, one near surfaces to 0.15 spacing
    # from them, at most 0.45 spacing per axis; the moved probes are captured again. Off: window-room
    # at two bounces 0.293 -> 0.243 and cornell-sun 0.286 -> 0.255 with it, but thin-wall 0.155 -> 0.173.
    relocate: bool = field(default=False, metadata={
        "doc": "move probes out of solids and off surfaces near them (at most 0.45 spacing per axis), from "
               "their own captures"})


@dataclass(frozen=True)
class GatherConfig(_Validated):
    """Distance-corrected final gathering from the probes' cube maps (method `gather`, paper 001):
    docs/GATHER.md. The probes' own settings (ProbesConfig) place and capture the cube maps."""

    # M: each probe face's face_texels^2 captured texels are merged into M x M quad lights, each rebuilt
    # at its measured corner distances (fine texels where a quad would straddle a depth edge). The
    # paper's M is 4 or 2. Must divide ProbesConfig.face_texels (the quads' corners are texel corners).
    face_quads: int = _num(4, 2, 8, "quad lights per side of each probe face (M x M per face; must divide "
                           "face_texels)")
    # polygon: the exact form factor of each quad at the receiver (Lambert's formula, clipped to the
    # receiver's horizon), bounded near walls; point: the paper's baseline, each quad a point light
    # A cos cos / (pi r^2), which spikes where a receiver is near a quad (docs/GATHER.md).
    form_factor: str = _choice("polygon", ("polygon", "point"), "each quad's form factor at the receiver: "
                               "polygon-to-point (exact, bounded) or point-to-point (the paper's baseline)")


@dataclass(frozen=True)
class DiffusionConfig(_Validated):
    """Volume diffusion (method `diffusion`, paper 000): docs/DIFFUSION.md derives the transport."""

    grid_cells: int = _num(32, 8, 256, "diffusion cells along the scene's longest side")
    # The single field's (cone_fields off). cone: the paper's transfer, each face's flux arriving as the
    # uniform cone of that face (normalised by 3 / (2 pi)); light forgets its direction at every cell and
    # diffuses (cornell rel_rmse_8 1.06). directional: LPV's improved transfer (docs/LPV.md), light keeps
    # its direction (0.57; docs/DIFFUSION.md, "Transfers").
    transfer: str = _choice("directional", ("directional", "cone"), "the single field's face transfer (cone fields "
                            "off): directional (LPV's improved: light keeps its direction) or cone (the paper's, "
                            "normalised)")
    # Light moves at most one cell per step, and this transport scatters it sideways at every cell, so
    # a bounce that crosses a room of Y cells needs several times Y steps to settle (docs/DIFFUSION.md,
    # "Steps"): what is still in flight after the last step is lost.
    steps_per_bounce: int = _num(0, 0, 4096, "propagation steps per bounce (0: span_multiple x the grid's longest "
                                 "side)")
    span_multiple: float = _num(2.0, 0.25, 16.0, "with steps_per_bounce 0: steps per bounce as a multiple of the "
                                "grid's longest side (1: the paper's rule)")
    max_steps: int = _num(512, 1, 8192, "cap on the steps of all bounces together")
    # On: each bounce is propagated once per emitter class (the sides whose normals share a dominant
    # signed axis) and a side takes in what every class but its own brought it, as lpv's emitter classes:
    # a plane cannot light itself, but the single field carried light leaving a plane back onto it (a lit
    # floor lit itself again; docs/DIFFUSION.md, "Emitter classes"). With the single field (cone_fields
    # off), at 32 cells, 128 px, rel_rmse_8 against Cycles, off -> on: window-room 1.155 -> 0.369 (two
    # bounces 0.619 -> 0.169), thin-wall 0.232 -> 0.129, cornell 0.433 -> 0.410. Off by default: the cone
    # fields keep most of that self-lighting out at the same six propagations, and both on take 36.
    emitter_class_passes: bool = field(default=False, metadata={
        "doc": "a side takes in no light from sides facing its way (six propagations per bounce)"})
    # On: the light heading through each cube face (the directions whose dominant signed axis is the
    # face's) is a field of its own, propagated apart (six propagations per bounce, times six with the
    # emitter classes) and never mixed with the others' in open space, so light rising past a wall is
    # not turned into it (cone_fields.py; docs/DIFFUSION.md, "Cone fields"). The transfer is then the
    # directional partition within each cone (`transfer` unused). At 32 cells, 128 px, against the single
    # field with the emitter classes: rel_rmse_8 lower on 13 of the 15 benchmark scenes at one and at two
    # bounces (cornell 0.422 -> 0.213); a sunlit room's one bounce worse (window-room 0.373 -> 0.505).
    cone_fields: bool = field(default=True, metadata={
        "doc": "propagate the light heading through each cube face as its own field (six per bounce)"})
    # On: the grid runs only its first near_steps and hands the light still in flight to a grid of twice
    # the cell (its own voxels and cells, aligned to the fine voxels) for the rest of the bounce
    # (docs/DIFFUSION.md, "Far field"). grid_cells >= 32: a coarser far grid resolves too little of a
    # room. At 32 cells, 128 px on llvmpipe: a lights update 0.64-0.70x of one grid's on the Cornell
    # boxes and thin-wall, 0.77-0.86x on window-room and the real scenes; rel_rmse_8 within 0.032
    # (cornell 0.412 -> 0.424, thin-wall 0.104 -> 0.104, conference 0.230 -> 0.230).
    far_field: bool = field(default=True, metadata={
        "doc": "carry light beyond the near steps on a grid of twice the cell size (faster, less on-axis excess)"})
    # Half the bounce's steps (the grid's span at span_multiple 2): a quarter (16 at 32 cells) made the
    # boxes' update 0.44-0.55x of one grid's but the error grew by up to 0.056 (cornell-area 0.251 ->
    # 0.307; docs/DIFFUSION.md).
    near_steps: int = _num(0, 0, 4096, "far field: steps the fine grid runs per bounce (0: half its steps per bounce)")


@dataclass(frozen=True)
class GIConfig(_Validated):
    """What to compute and at which output resolution."""

    # rsm: the best error for its time on the benchmark scenes at 128 px (benchmarks/REPORT.md: Cycles'
    # time to its error over its own time is 1.5x on cornell at 256 VPLs, lpv 0.28x, vct 0.24x), and a
    # default that adds indirect light, so a first Enable and a first Bake show something.
    method: str = _choice("rsm", METHODS, "GI method")
    bounces: int = _num(1, 1, 8, "indirect diffuse bounces (Cycles diffuse_bounces)")
    resolution: int = _num(256, 8, 8192, "long side of the output image in pixels")
    # On: the products of the stochastic gathers (rsm's VPLs, vct's jittered cones) are filtered along
    # their surfaces, guided by the G-buffer (passes/denoise.py): vct's per-pixel rel_rmse on cornell
    # 0.17 (0.60 unfiltered) for 1-6 % of its update. Off: the raw gather, as the papers describe it.
    # Progressive refinement: a render or bake averages this many gathers of the stochastic methods,
    # each with other VPLs / cone rotations (DirectMethod.refine; noise / sqrt(samples)); the viewport
    # keeps adding gathers while nothing changes.
    samples: int = _num(1, 1, 1024, "gathers averaged per render or bake (rsm, vct: noise falls as 1 / sqrt)")
    # The denoise filter's reach is a fixed share of the image (denoise.iterations_for), so a small image
    # leaves it few samples to average: the viewport's 256 px (128 while moving) and the benchmarks' 128 px
    # are small. There the stochastic gathers sample every pixel budget / pixels times (at most 4;
    # surface_support.image_samples), which a GPU does in a fraction of a millisecond at those sizes
    # (docs/ARCHITECTURE.md, "A clean preview").
    sample_budget_px: int = _num(518400, 0, 1 << 24, "pixel samples an update of rsm or vct spends: an image with "
                                 "fewer pixels samples each pixel several times (up to 4; 0: once)")
    denoise: bool = field(default=True, metadata={
        "doc": "filter the stochastic gathers' noise along each surface (never across edges)"})
    seed: int = _num(0, 0, 2**31 - 1, "seed of every stochastic choice")


# Settings group -> its config class: the Blender property groups (scene.bounce.<group>), the command
# line's flags and the registry's `reads` use these names.
GROUPS: dict[str, type] = {"gi": GIConfig, "rsm": RsmConfig, "lpv": LpvConfig, "vct": VctConfig,
                           "probes": ProbesConfig, "diffusion": DiffusionConfig, "gather": GatherConfig}


def settings(**configs) -> dict[str, Any]:
    """{group: config} for every group of GROUPS: the given configs, each group's defaults for the rest.
    What a method is built from (methods.create), and what scene.bounce, the command line and the
    benchmark settings turn into, so no caller lists the groups."""
    unknown = sorted(set(configs) - set(GROUPS))
    if unknown:
        raise ConfigError(f"unknown settings group(s) {', '.join(unknown)}; known: {', '.join(GROUPS)}")
    out = {}
    for group, cls in GROUPS.items():
        value = configs.get(group)
        if value is not None and not isinstance(value, cls):
            raise ConfigError(f"settings group {group!r} takes a {cls.__name__}, got {type(value).__name__}")
        out[group] = cls() if value is None else value
    return out


def limits(cls) -> dict[str, dict[str, Any]]:
    """Field name -> {'default', 'min'/'max' or 'choices', 'doc'}: what Blender properties mirror."""
    out = {}
    for f in dataclasses.fields(cls):
        out[f.name] = {"default": f.default, **dict(f.metadata)}
    return out
