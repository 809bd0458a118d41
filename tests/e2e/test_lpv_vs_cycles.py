"""Method `lpv`, both transport variants, against Cycles' Diffuse Indirect on the Cornell box (64 px).

BASELINE.md measured classic LPV (as published) at rel_rmse_8 ~0.96 at best on this scene at 128 px,
no better than a constant. The issue's target for the improved variant is rel_rmse_8 <= 0.45 with
bias 0.8..1.25: the default (surface offsets, far field) reads 0.326 / 0.928 (0.474 / 1.202 on one
grid without the far field). The bounds below are the figures measured here (in comments) with a
margin; the reference (256 spp) has rel_rmse_8 ~0.02 on its own, far below every bound.
"""

import pytest

pytestmark = [pytest.mark.blender, pytest.mark.slow]

RES = 64


def render_lpv(blend, lpv_config, res=RES, bounces=1):
    """Capture `blend` and run LpvMethod with `lpv_config` (pipeline.render_file builds methods with
    their default config): returns the indirect image and the update's timings."""
    import bpy

    from addon.bridge.capture import SceneCache, define_light_switch, image_size
    from addon.bridge.pipeline import backend, open_blend
    from addon.engine.config import GIConfig, RsmConfig
    from addon.engine.methods.lpv import LpvMethod

    open_blend(blend)
    define_light_switch()
    width, height = image_size(bpy.context.scene, res)
    scene = SceneCache().update(bpy.context.evaluated_depsgraph_get(), width, height)
    method = LpvMethod(backend(), GIConfig(method="lpv", resolution=res, bounces=bounces), RsmConfig(), lpv_config)
    method.set_scene(scene)
    method.run()  # warm-up: programs compiled
    result = method.run()
    return result.images["indirect"], result.timings_ms


def scene_and_reference(tmp_path, name, bounces=1):
    """Procedural scene `name` saved under tmp_path and Cycles' Diffuse Indirect of it (256 spp, RES):
    (blend path, reference RGBA, mask of the pixels with geometry)."""
    from addon.bridge import images, scenes
    from addon.bridge.reference import render_reference

    blend = tmp_path / f"{name}.blend"
    scenes.save(name, blend)
    render_reference(blend, tmp_path / "ref", spp=256, bounces=bounces, res=RES, seed=0)
    ref = images.read_exr(tmp_path / "ref" / "indirect.exr")
    return blend, ref, ref[..., 3] > 0.5


def test_lpv_variants_on_cornell(tmp_path):
    from addon.engine import metrics
    from addon.engine.config import LpvConfig

    blend, ref, mask = scene_and_reference(tmp_path, "cornell", bounces=1)
    errors = {}
    for name, cfg in {
        "classic": LpvConfig(variant="classic", geometry_volume=True),
        "improved": LpvConfig(variant="improved", geometry_volume=True),
        "improved, no surface offsets": LpvConfig(variant="improved", geometry_volume=True, surface_offsets=False),
        "improved, one grid": LpvConfig(variant="improved", geometry_volume=True, far_field=False),
        "improved, emitter classes": LpvConfig(variant="improved", geometry_volume=True, emitter_classes=True),
    }.items():
        ours, timings = render_lpv(blend, cfg)
        errors[name] = metrics.compare(ours, ref, mask)
        print(f"lpv {name} vs Cycles: {errors[name]}, total {timings['total']:.0f} ms, "
              f"propagate {timings['lpv_propagate']:.0f} ms")
    classic, improved = errors["classic"], errors["improved"]
    aligned, one_grid = errors["improved, no surface offsets"], errors["improved, one grid"]
    # Measured at 64 px, 32-cell grid, geometry volume on (llvmpipe):
    # classic (16 iterations): rel_rmse 1.37, rel_rmse_8 1.17, bias 0.46 (without GV: 1.37, 0.69;
    # BASELINE at 128 px: 1.50, 0.46 for 32^3 + GV). Band: as bad as BASELINE says, not worse.
    assert 0.9 <= classic["rel_rmse_8"] <= 1.5
    assert 0.2 <= classic["bias"] <= 0.7
    # improved on one grid (far_field=False; 93 iterations = the grid's Manhattan span), geometry-aware
    # lookup, blocking by projected area, surface offsets: rel_rmse 0.613, rel_rmse_8 0.474, bias 1.202
    # (without offsets 0.441 / 1.141; plain trilinear lookup: 0.456 / 0.797). Over the target: the L1 transfer
    # over-reads along the axes, more the more steps light takes (docs/LPV.md, "Measured limits").
    # The default adds the far field (16 steps on this grid, the rest on a 16-cell grid: half the steps
    # for the same distance): rel_rmse 0.457, rel_rmse_8 0.326, bias 0.928; without surface offsets
    # 0.333 / 0.932. Both meet the target; the default's bound is its figure plus llvmpipe's
    # run-to-run spread (below 0.005) and a margin, so a regression fails; the far field must earn
    # its place (at least a fifth less error than one grid).
    assert improved["rel_rmse_8"] <= 0.34
    assert 0.8 <= improved["bias"] <= 1.25
    assert aligned["rel_rmse_8"] <= 0.45
    assert 0.8 <= aligned["bias"] <= 1.25
    assert improved["rel_rmse_8"] < 0.8 * one_grid["rel_rmse_8"]
    assert improved["rel_rmse_8"] < 0.5 * classic["rel_rmse_8"]
    # Emitter classes (the floor and box tops no longer cancel the light arriving at them): 0.287 /
    # 0.947, rel_rmse 0.416. Bound: its figure plus the spread and a margin, and a tenth below the
    # default's error measured in the same run (0.88 of it), so classes that stop helping fail.
    classes = errors["improved, emitter classes"]
    assert classes["rel_rmse_8"] <= 0.30
    assert 0.85 <= classes["bias"] <= 1.15
    assert classes["rel_rmse_8"] < 0.92 * improved["rel_rmse_8"]


def test_lpv_second_bounce_on_cornell(tmp_path):
    """Improved variant, 32 cells, geometry volume, bounces=2 vs Cycles' Diffuse Indirect at
    diffuse_bounces=2 (256 spp, 64 px). Measured (llvmpipe, 2 cores; geometry-aware lookup, surface
    offsets, re-injection from the corners that do not block along the side, far field):
    - bounces=2: rel_rmse 0.384, rel_rmse_8 0.280, bias 0.857; update ~0.3 s.
    - bounces=1 against the same reference: rel_rmse 0.481, rel_rmse_8 0.405, bias 0.664.
    - the second bounce raises our mean by 1.29x; Cycles' by 1.40x (2-bounce / 1-bounce reference).
    (On one grid, far_field=False: 0.378 / 1.153 and 0.331 / 0.859, the L1 transfer's on-axis excess
    lifting both.)
    The reference's own noise (seed 0 vs seed 1): rel_rmse_8 0.024, bias 0.995. The bounds sit a little
    outside the 2-bounce figures and exclude the 1-bounce ones, so a missing or halved second bounce
    fails (bias, ratio), as does one that adds error (rel_rmse_8).
    """
    from addon.engine import metrics
    from addon.engine.config import LpvConfig

    blend, ref, mask = scene_and_reference(tmp_path, "cornell", bounces=2)
    cfg = LpvConfig(variant="improved", geometry_volume=True)
    errors, means = {}, {}
    for bounces in (1, 2):
        ours, timings = render_lpv(blend, cfg, bounces=bounces)
        errors[bounces] = metrics.compare(ours, ref, mask)
        means[bounces] = ours[mask][:, :3].mean()
        print(f"lpv improved, bounces={bounces} vs Cycles diffuse_bounces=2: {errors[bounces]}, "
              f"total {timings['total']:.0f} ms")
    two = errors[2]
    assert two["rel_rmse_8"] <= 0.30
    assert 0.8 <= two["bias"] <= 1.2
    assert means[2] / means[1] >= 1.2
    # The bounds can fail: one bounce scores outside the bias band (its rel_rmse_8 is as low: the
    # pattern is right, the level is not).
    assert errors[1]["bias"] < 0.8


def test_surface_offsets_on_thin_wall(tmp_path):
    """thin-wall (a lit 2 m room of walls 0.1 m thick, thinner than a 0.13 m cell, at positions that do
    not align with cells) vs Cycles, 64 px, 256 spp, improved, 32 cells, on one grid (far_field=False,
    which isolates the offsets). Without surface offsets a VPL
    that lands in the cell of its own wall (the wall in the cell's near 40 %) loses half its light on
    its first step out, so the room's light depends on how its walls fall in cells: at 128 px rel_rmse_8
    0.28 / 0.64 / 0.68 / 0.29 / 0.53 at 16 / 24 / 32 / 48 / 64 cells (bias 0.56 at 32), with offsets
    0.30 / 0.30 / 0.22 / 0.31 / 0.28 (docs/LPV.md). Measured here at 64 px: see the printed figures;
    without offsets rel_rmse_8 0.617 / bias 0.569, with offsets 0.178 / 0.929. Bounds between the two
    (the reference alone reads ~0.03), so either transport's regression fails. The default (offsets and
    the far field, whose 16-cell grid holds these walls less well) reads 0.242 / 0.849: bounded too.
    With emitter classes (the lit floor reads the walls' light instead of cancelling it) 0.111 / 0.979:
    bounded at its figure with a margin, and below 0.6 x the default's error in the same run."""
    from addon.engine import metrics
    from addon.engine.config import LpvConfig

    blend, ref, mask = scene_and_reference(tmp_path, "thin-wall", bounces=1)
    errors = {}
    for name, cfg in {
        "no offsets, one grid": LpvConfig(surface_offsets=False, far_field=False),
        "offsets, one grid": LpvConfig(far_field=False),
        "default": LpvConfig(),
        "emitter classes": LpvConfig(emitter_classes=True),
    }.items():
        ours, _ = render_lpv(blend, cfg)
        errors[name] = metrics.compare(ours, ref, mask)
        print(f"lpv thin-wall, {name}: {errors[name]}")
    offsets, no_offsets, default = errors["offsets, one grid"], errors["no offsets, one grid"], errors["default"]
    assert offsets["rel_rmse_8"] <= 0.3 and 0.85 <= offsets["bias"] <= 1.15
    assert no_offsets["rel_rmse_8"] > 0.5 and no_offsets["bias"] < 0.7
    assert default["rel_rmse_8"] <= 0.3 and 0.8 <= default["bias"] <= 1.15
    classes = errors["emitter classes"]
    assert classes["rel_rmse_8"] <= 0.13 and 0.9 <= classes["bias"] <= 1.1
    assert classes["rel_rmse_8"] < 0.6 * default["rel_rmse_8"]


def test_lpv_octree_on_cornell(tmp_path):
    """The octree variant (docs/LPV.md, "Octree") against Cycles on the Cornell box, 64 px, one bounce:
    the paper's settings (5 levels, k = 4, the finest level with non-zero light, every level blocked), the
    index merge at the paper's k with eps 0.5 and three blocked levels (the issue's target: rel_rmse_8
    <= 0.40, bias 0.8..1.25 at k = 4), and the defaults (time merge, 4 levels, k = 12)."""
    from addon.engine import metrics
    from addon.engine.config import LpvConfig

    blend, ref, mask = scene_and_reference(tmp_path, "cornell", bounces=1)
    errors = {}
    for name, cfg in {
        "paper": LpvConfig(variant="octree", octree_merge="index", octree_levels=5, octree_iterations=4,
                           octree_epsilon=1e-6, octree_blocked_levels=5),
        "index": LpvConfig(variant="octree", octree_merge="index", octree_levels=5, octree_iterations=4),
        "default": LpvConfig(variant="octree"),
        "far field": LpvConfig(variant="improved", geometry_volume=True),
    }.items():
        ours, timings = render_lpv(blend, cfg)
        errors[name] = metrics.compare(ours, ref, mask)
        print(f"lpv octree {name} vs Cycles: {errors[name]}, propagate {timings['lpv_propagate']:.0f} ms")
    paper, index, default = errors["paper"], errors["index"], errors["default"]
    # Measured at 64 px (llvmpipe), rel_rmse_8 / bias: paper 0.942 / 0.205, index 0.342 / 0.899, default
    # 0.290 / 0.800, far field (lpv's default) 0.326 / 0.928. Bounds: each figure plus llvmpipe's
    # run-to-run spread (below 0.005) and a margin. The paper's rule is banded as measured, as dark as its
    # frontier light winning the level switch makes it (a change either way shows); the default must stay
    # below the far field's error on this scene, the one where it is better (docs/LPV.md, "Octree").
    assert 0.8 <= paper["rel_rmse_8"] <= 1.2 and 0.1 <= paper["bias"] <= 0.4
    assert index["rel_rmse_8"] <= 0.36 and 0.8 <= index["bias"] <= 1.25
    assert default["rel_rmse_8"] <= 0.31 and 0.75 <= default["bias"] <= 1.25
    assert default["rel_rmse_8"] < 0.95 * errors["far field"]["rel_rmse_8"]
