"""A light that cannot reach the geometry gets no light view, and the images stay exactly those of the
scene without it (light_views.reaches)."""

from dataclasses import replace

import numpy as np
import pytest

pytestmark = [pytest.mark.blender, pytest.mark.gpu]
bpy = pytest.importorskip("bpy")


def test_a_spot_aimed_away_costs_nothing_and_changes_nothing(gl):
    from addon.bridge import scenes
    from addon.bridge.capture import SceneCache
    from addon.engine import methods
    from addon.engine.config import GIConfig, RsmConfig
    from addon.engine.scene import Light

    scenes.build("cornell")
    scene = SceneCache().update(bpy.context.evaluated_depsgraph_get(), 24, 24)
    away = Light("SPOT", np.array([0.0, 0.0, 30.0]), np.array([0.0, 0.0, 1.0]), np.ones(3), power_w=1000.0,
                 spot_size_rad=np.radians(30.0))
    images, views = [], []
    for lights in (scene.lights, [*scene.lights, away]):
        method = methods.create(gl, {"gi": GIConfig(method="rsm", resolution=24),
                                     "rsm": RsmConfig(resolution=32, vpl_samples=16)})
        method.set_scene(replace(scene, lights=list(lights)))
        method.compute()
        images.append(method.read())
        views.append(len(method.light_views()))
    assert views[0] == views[1] > 0
    for key in images[0]:
        np.testing.assert_array_equal(images[0][key], images[1][key], err_msg=key)
