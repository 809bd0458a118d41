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


def test_in_turn_alternates_the_methods_round_by_round(gl):
    # The benchmark times a scene's rows in turn so that the machine's load drifting over minutes falls
    # alike on every row: round r times one update of each kind of every method before round r + 1 starts.
    # Each update_costs(method, 1) computes 4 times (full, lights, camera, restoring the caller's state),
    # so 2 methods x 3 rounds must read A A A A B B B B, three times over.
    from addon.bridge import scenes
    from addon.bridge.capture import SceneCache
    from addon.engine import methods
    from addon.engine.config import GIConfig, LpvConfig, RsmConfig
    from addon.engine.updates import update_costs_in_turn

    scenes.build("cornell")
    scene = SceneCache().update(bpy.context.evaluated_depsgraph_get(), 24, 24)
    order = []
    warm = []
    for name in ("direct", "lpv"):
        method = methods.create(gl, {"gi": GIConfig(method=name, resolution=24), "rsm": RsmConfig(resolution=32),
                                     "lpv": LpvConfig(grid_cells=16)})
        method.set_scene(scene)
        method.compute()
        compute = method.compute
        method.compute = lambda *a, _c=compute, _n=name, **k: (order.append(_n), _c(*a, **k))[1]
        warm.append(method)
    costs = update_costs_in_turn(warm, rounds=3)
    assert order == (["direct"] * 4 + ["lpv"] * 4) * 3
    assert len(costs) == 2
    assert all(set(c) == {"full", "lights", "camera"} and all(ms > 0 for ms in c.values()) for c in costs)
