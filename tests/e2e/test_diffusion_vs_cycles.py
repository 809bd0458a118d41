"""Method `diffusion` against Cycles' Diffuse Indirect on the Cornell box (64 px, one bounce).

The issue's target is cornell rel_rmse_8 <= 0.30, bias 0.85..1.15 at 32 cells. The default cone fields
keep the light heading through each cube face apart, so light rising past a wall is not turned into it
(docs/DIFFUSION.md, "Cone fields"); the single field with the emitter classes (the directional transfer)
and the paper's face-cone transfer drain the box's light into its walls on its way. The bounds are the
figures measured here (in comments) with a margin, so a change of the transport shows; the reference
(256 spp) has rel_rmse_8 ~0.02 on its own, far below every bound.
"""

import pytest

pytestmark = [pytest.mark.blender, pytest.mark.slow]

RES = 64


def test_diffusion_on_cornell(tmp_path):
    import bpy

    from addon.bridge import images, scenes
    from addon.bridge.capture import SceneCache, define_light_switch, image_size
    from addon.bridge.pipeline import backend, open_blend
    from addon.bridge.reference import render_reference
    from addon.engine import methods, metrics
    from addon.engine.config import DiffusionConfig, GIConfig

    blend = tmp_path / "cornell.blend"
    scenes.save("cornell", blend)
    render_reference(blend, tmp_path / "ref", spp=256, bounces=1, res=RES, seed=0)
    ref = images.read_exr(tmp_path / "ref" / "indirect.exr")
    open_blend(blend)
    define_light_switch()
    width, height = image_size(bpy.context.scene, RES)
    scene = SceneCache().update(bpy.context.evaluated_depsgraph_get(), width, height)
    errors = {}
    single = {"cone_fields": False, "emitter_class_passes": True}
    variants = {"cones": {}, "directional": single, "cone": {**single, "transfer": "cone"}}
    for name, fields in variants.items():
        for cells in (16, 32):
            method = methods.create(backend(), {"gi": GIConfig(method="diffusion", resolution=RES),
                                                "diffusion": DiffusionConfig(grid_cells=cells, **fields)})
            method.set_scene(scene)
            errors[name, cells] = metrics.compare(method.run().images["indirect"], ref, ref[..., 3] > 0.5)
            print(f"diffusion {name} {cells} cells vs Cycles: {errors[name, cells]}")
    # Measured (llvmpipe, 64 px), rel_rmse_8 / bias at 16 and 32 cells: cone fields (the defaults) 0.159 /
    # 0.969 and 0.186 / 0.923; the single field, directional 0.292 / 0.922 and 0.388 / 0.871; the paper's
    # transfer 0.555 / 0.735 and 0.735 / 0.549. The default is held to the target itself.
    default = errors["cones", 32]
    assert default["rel_rmse_8"] <= 0.30
    assert 0.85 <= default["bias"] <= 1.15
    # The single field drains the light into the walls, and the paper's transfer diffuses it further.
    for cells in (16, 32):
        assert errors["cones", cells]["rel_rmse_8"] < errors["directional", cells]["rel_rmse_8"] \
            < errors["cone", cells]["rel_rmse_8"]
