"""Method `vct` against Cycles' Diffuse Indirect on the Cornell box (64 px), one and two bounces.

The issue's target is rel_rmse_8 <= 0.15 with bias 0.9..1.1 (one bounce); measured here: 0.117 /
0.953 with the default denoise filter (docs/VCT.md, "Alternatives measured", for the choices behind
it). The bounds are the measured figures (in comments) with a margin; the references (256 spp) have
rel_rmse_8 ~0.02 on their own, far below every bound.
"""

import pytest

pytestmark = [pytest.mark.blender, pytest.mark.slow]

RES = 64


def render_vct(blend, gi, vct_config):
    import bpy

    from addon.bridge.capture import SceneCache, define_light_switch, image_size
    from addon.bridge.pipeline import backend, open_blend
    from addon.engine.config import RsmConfig
    from addon.engine.methods.vct import VctMethod

    open_blend(blend)
    define_light_switch()
    width, height = image_size(bpy.context.scene, RES)
    scene = SceneCache().update(bpy.context.evaluated_depsgraph_get(), width, height)
    method = VctMethod(backend(), gi, RsmConfig(), vct_config)
    method.set_scene(scene)
    result = method.run()
    return result.images["indirect"], result.timings_ms


def test_vct_on_cornell_one_and_two_bounces(tmp_path):
    import numpy as np

    from addon.bridge import images, scenes
    from addon.bridge.reference import render_reference
    from addon.engine import metrics
    from addon.engine.config import GIConfig, VctConfig

    blend = tmp_path / "cornell.blend"
    scenes.save("cornell", blend)
    refs = {}
    for bounces in (1, 2):
        render_reference(blend, tmp_path / f"ref{bounces}", spp=256, bounces=bounces, res=RES, seed=0)
        refs[bounces] = images.read_exr(tmp_path / f"ref{bounces}" / "indirect.exr")
    mask = refs[1][..., 3] > 0.5

    one, t1 = render_vct(blend, GIConfig(method="vct", resolution=RES), VctConfig())
    e1 = metrics.compare(one, refs[1], mask)
    print(f"vct 1 bounce, 64 cells, 16 cones: {e1}, total {t1['total']:.0f} ms")
    # Measured (llvmpipe, denoise on, interleaved cones): rel_rmse_8 0.122, bias 0.941. rsm without
    # visibility scores 0.18 / 1.13.
    assert e1["rel_rmse_8"] <= 0.18
    assert 0.88 <= e1["bias"] <= 1.0

    # Two bounces on a 32-cell grid (the voxel gather costs ~0.6 s per bounce on llvmpipe at 32 cells).
    small = VctConfig(voxel_cells=32)
    two, t2 = render_vct(blend, GIConfig(method="vct", resolution=RES, bounces=2), small)
    one_small, _ = render_vct(blend, GIConfig(method="vct", resolution=RES), small)
    e2 = metrics.compare(two, refs[2], mask)
    e1_vs_2 = metrics.compare(one_small, refs[2], mask)
    print(f"vct 2 bounces, 32 cells: {e2}, total {t2['total']:.0f} ms; 1 bounce vs the 2-bounce reference: "
          f"{e1_vs_2}")
    assert np.isfinite(two).all() and (two >= 0).all()
    # Measured: rel_rmse_8 0.105, bias 0.975 against Cycles at diffuse_bounces = 2; one bounce reads bias 0.70
    # against that reference, outside the band, so a missing second bounce fails here. Bias bounds:
    # the 0.9..1.1 widened below by 0.05.
    assert e2["rel_rmse_8"] <= 0.18
    assert 0.85 <= e2["bias"] <= 1.1
    assert not 0.85 <= e1_vs_2["bias"]


def test_vct_glossy_on_cornell_glossy(tmp_path):
    """The `glossy` product against Cycles' Glossy Color x Glossy Indirect (reference --glossy, one
    glossy bounce) on cornell-glossy: a polished floor (F0 0.08, roughness 0.2) and satin boxes (0.45).
    Measured (64 px, 64 cells, 8 specular cones): rel_rmse_8 0.388, bias 0.868 (one cone as wide as the
    lobe: 1.18 / 0.76; 128 cells: 0.34 / 0.89); the reference's own noise 0.030 (seed 0 vs 1). Bounds:
    rel_rmse_8 <= 0.5, bias 0.75..1.0 (the pyramid is darker than Cycles, as for diffuse light)."""
    import numpy as np

    from addon.bridge import images, scenes
    from addon.bridge.capture import SceneCache, define_light_switch, image_size
    from addon.bridge.pipeline import backend, open_blend
    from addon.bridge.reference import render_reference
    from addon.engine import metrics
    from addon.engine.config import GIConfig, RsmConfig, VctConfig
    from addon.engine.methods.vct import VctMethod

    blend = tmp_path / "cornell-glossy.blend"
    scenes.save("cornell-glossy", blend)
    render_reference(blend, tmp_path / "ref", spp=256, bounces=1, res=RES, seed=0, glossy=True)
    ref = images.read_exr(tmp_path / "ref" / "glossy.exr")
    import bpy

    open_blend(blend)
    define_light_switch()
    width, height = image_size(bpy.context.scene, RES)
    scene = SceneCache().update(bpy.context.evaluated_depsgraph_get(), width, height)
    assert scene.specular.max() == np.float32(0.08)
    method = VctMethod(backend(), GIConfig(method="vct", resolution=RES), RsmConfig(), VctConfig())
    method.set_scene(scene)
    result = method.run()
    ours = result.images["glossy"]
    err = metrics.compare(ours, ref, ref[..., 3] > 0.5)
    print(f"vct glossy: {err}, glossy pass {result.timings_ms['vct_glossy']:.0f} ms")
    assert np.isfinite(ours).all() and (ours >= 0).all()
    assert err["rel_rmse_8"] <= 0.5
    assert 0.75 <= err["bias"] <= 1.0
