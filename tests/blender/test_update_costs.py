"""engine.updates.update_costs: what each of the three kinds of update re-runs (render --profile-updates)."""

import pytest

pytestmark = [pytest.mark.blender, pytest.mark.gpu]
bpy = pytest.importorskip("bpy")


def test_full_is_a_geometry_change_lights_and_camera_are_not(gl):
    # The definition: a geometry change re-runs everything (the upload and the setup passes
    # with it), a light change the light views, solve and gathers, a camera change the G-buffer and
    # gathers. Counted: set_scene once per full update only, a solve per full and per lights update.
    from addon.bridge import scenes
    from addon.bridge.capture import SceneCache
    from addon.engine import methods
    from addon.engine.config import GIConfig, LpvConfig, RsmConfig
    from addon.engine.updates import update_costs

    scenes.build("cornell")
    scene = SceneCache().update(bpy.context.evaluated_depsgraph_get(), 24, 24)
    method = methods.create(gl, {"gi": GIConfig(method="lpv", resolution=24), "rsm": RsmConfig(resolution=32),
                                 "lpv": LpvConfig(grid_cells=16)})
    method.set_scene(scene)
    method.compute()
    uploads = []
    set_scene = method.set_scene
    method.set_scene = lambda s: (uploads.append(s), set_scene(s))[1]
    costs = update_costs(method, repeat=3)
    assert len(uploads) == 3 and all(s.positions_m is scene.positions_m for s in uploads)
    # set_scene starts the count again: since the last full update, it solved, the lights update
    # solved, the camera update did not, and the update restoring the caller's lights solved: 3
    assert method.solves == 3
    assert set(costs) == {"full", "lights", "camera"} and all(ms > 0 for ms in costs.values())
