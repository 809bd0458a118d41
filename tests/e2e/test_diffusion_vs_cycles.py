"""Method `diffusion` against Cycles' Diffuse Indirect on the Cornell box (64 px, one bounce).

The issue's target (cornell rel_rmse_8 <= 0.30, bias 0.85..1.15) is out of reach at the default 32
cells: the paper's face-cone transfer makes light diffuse, so light leaving a surface wanders back onto
it (the emitter classes drop what reaches its own plane) and far surfaces starve; the default
directional transfer halves that error (docs/DIFFUSION.md, "Measured limits"). The bounds are the figures measured
here (in comments) with a margin, so a change of the transport shows; the reference (256 spp) has
rel_rmse_8 ~0.02 on its own, far below every bound.
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
    for transfer in ("directional", "cone"):
        for cells in (16, 32):
            method = methods.create(backend(), {"gi": GIConfig(method="diffusion", resolution=RES),
                                                "diffusion": DiffusionConfig(grid_cells=cells, transfer=transfer)})
            method.set_scene(scene)
            errors[transfer, cells] = metrics.compare(method.run().images["indirect"], ref, ref[..., 3] > 0.5)
            print(f"diffusion {transfer} {cells} cells vs Cycles: {errors[transfer, cells]}")
    # Measured (llvmpipe, 64 px, emitter classes on, the default): directional 16 cells rel_rmse_8
    # 0.292, bias 0.922; 32 cells (the default) 0.373, 0.922; cone (the paper's) 16 cells 0.555, 0.735;
    # 32 cells 0.785, 0.498 (the light the cone transfer carries back onto its own plane is dropped).
    # The default within about 0.1 of its figures.
    default = errors["directional", 32]
    assert 0.29 <= default["rel_rmse_8"] <= 0.50
    assert 0.85 <= default["bias"] <= 1.05
    # The paper's transfer diffuses light: worse at every grid; and a finer grid scatters light at more
    # cells, so both are worse at 32 cells than at 16.
    for cells in (16, 32):
        assert errors["directional", cells]["rel_rmse_8"] < errors["cone", cells]["rel_rmse_8"]
    for transfer in ("directional", "cone"):
        assert errors[transfer, 16]["rel_rmse_8"] < errors[transfer, 32]["rel_rmse_8"]
