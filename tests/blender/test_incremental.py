"""Incremental updates: a camera move gathers from the kept light field (no solve) and a light move
solves again, and either gives exactly the images of a method set up from scratch for the new state.

Bitwise: the same passes run on the same inputs in the same order (RSM faces kept per face instead of
one shared RSM redrawn per face), so nothing may differ, not even in the last bit."""

from dataclasses import replace

import numpy as np
import pytest

pytestmark = [pytest.mark.blender, pytest.mark.gpu]
bpy = pytest.importorskip("bpy")

# (method, GIConfig, LpvConfig, VctConfig overrides, whether a camera move keeps the light field)
CASES = {
    "direct": ("direct", {}, {}, {}, True),
    "rsm": ("rsm", {}, {}, {}, True),
    "lpv": ("lpv", {}, {"grid_cells": 16}, {}, True),
    "lpv-classes": ("lpv", {}, {"grid_cells": 16, "emitter_classes": True}, {}, True),
    "lpv-cascades": ("lpv", {}, {"grid_cells": 16, "cascades": 2}, {}, False),
    "lpv-2-bounces": ("lpv", {"bounces": 2}, {"grid_cells": 16}, {}, False),
    "lpv-octree": ("lpv", {}, {"grid_cells": 16, "variant": "octree"}, {}, True),
    "lpv-octree-index": ("lpv", {}, {"grid_cells": 16, "variant": "octree", "octree_merge": "index"}, {}, True),
    "lpv-octree-2-bounces": ("lpv", {"bounces": 2}, {"grid_cells": 16, "variant": "octree"}, {}, False),
    "vct": ("vct", {}, {}, {"voxel_cells": 16, "diffuse_cones": 6}, True),
    "vct-2-bounces": ("vct", {"bounces": 2}, {}, {"voxel_cells": 16, "diffuse_cones": 6}, True),
    # diffusion (16 cells, _method): its light field does not depend on the camera, bounces included.
    "diffusion": ("diffusion", {}, {}, {}, True),
    "diffusion-2-bounces": ("diffusion", {"bounces": 2}, {}, {}, True),
    # probes (6 a side, _method): the SH field does not depend on the camera, bounces included.
    "probes": ("probes", {}, {}, {}, True),
    "probes-2-bounces": ("probes", {"bounces": 2}, {}, {}, True),
    # gather (the probes' 6 a side): its quads do not depend on the camera, bounces included.
    "gather": ("gather", {}, {}, {}, True),
    "gather-2-bounces": ("gather", {"bounces": 2}, {}, {}, True),
}


def _moved_camera(camera, dx_m):
    view = camera.view.copy()
    view[0, 3] -= dx_m  # the camera moves +dx along its own right axis
    return replace(camera, view=view)


def _moved_lights(lights, dz_m):
    return [replace(light, position_m=light.position_m + np.array([0.0, 0.0, dz_m])) for light in lights]


@pytest.fixture(scope="module")
def cornell_scene():
    from addon.bridge import scenes
    from addon.bridge.capture import SceneCache

    scenes.build("cornell-glossy")  # glossy: vct's glossy gather reads the camera position
    return SceneCache().update(bpy.context.evaluated_depsgraph_get(), 32, 32)


def _method(gl, case):
    from addon.engine import methods
    from addon.engine.config import DiffusionConfig, GIConfig, LpvConfig, ProbesConfig, RsmConfig, VctConfig

    name, gi, lpv, vct, _ = CASES[case]
    return methods.create(gl, {"gi": GIConfig(method=name, resolution=32, **gi),
                               "rsm": RsmConfig(resolution=64, vpl_samples=16), "lpv": LpvConfig(**lpv),
                               "vct": VctConfig(**vct), "diffusion": DiffusionConfig(grid_cells=16),
                               "probes": ProbesConfig(probes_per_side=6)})


def _fresh_images(gl, case, scene):
    method = _method(gl, case)
    method.set_scene(scene)
    method.compute()
    return method.read()


def _assert_same(images, expected):
    assert set(images) == set(expected)
    for key in images:
        assert images[key][..., :3].max() > 0 or key in ("glossy", "ao"), key
        np.testing.assert_array_equal(images[key], expected[key], err_msg=key)


@pytest.mark.parametrize("case", CASES)
def test_camera_move_gathers_only(gl, cornell_scene, case):
    method = _method(gl, case)
    method.set_scene(cornell_scene)
    method.compute()
    assert method.solves == 1
    moved = _moved_camera(cornell_scene.camera, 0.01)
    method.set_camera(moved)
    timings = method.compute()
    keeps = CASES[case][4]
    assert method.solves == (1 if keeps else 2)
    assert ("rsm" in timings) != keeps  # no RSM is redrawn when the light field is kept
    _assert_same(method.read(), _fresh_images(gl, case, replace(cornell_scene, camera=moved)))


@pytest.mark.parametrize("case", CASES)
def test_light_move_solves_again(gl, cornell_scene, case):
    method = _method(gl, case)
    method.set_scene(cornell_scene)
    method.compute()
    lights = _moved_lights(cornell_scene.lights, -0.01)
    method.set_lights(lights)
    method.compute(run_gbuffer=False)  # the G-buffer is still valid: what the viewport runs
    assert method.solves == 2
    _assert_same(method.read(), _fresh_images(gl, case, replace(cornell_scene, lights=lights)))


@pytest.mark.parametrize("case", ["probes", "gather"])
def test_lights_removed_leave_no_light(gl, cornell_scene, case):
    # No pass zeroes the probes' atlas before a solve: the solve's first light face replaces the last
    # solve's light. With every light gone there is no first face, and the atlas must still go dark.
    method = _method(gl, case)
    method.set_scene(cornell_scene)
    method.compute()
    assert method.read()["indirect"][..., :3].max() > 0
    method.set_lights([])
    method.compute(run_gbuffer=False)
    assert method.read()["indirect"][..., :3].max() == 0.0


def test_lights_changed_in_place_are_noticed(gl, cornell_scene):
    # The light field remembers the lights it was solved for, not whether set_lights was called.
    method = _method(gl, "rsm")
    scene = replace(cornell_scene, lights=list(cornell_scene.lights))
    method.set_scene(scene)
    method.compute()
    scene.lights[0] = replace(scene.lights[0], power_w=scene.lights[0].power_w * 2)
    method.compute()
    assert method.solves == 2


def test_too_many_faces_to_keep_solve_every_update(gl, monkeypatch):
    # Over the RSM budget (here: one face kept, a point light has six) every face shares one RSM,
    # redrawn at every update, with the same images.
    from addon.bridge import scenes
    from addon.bridge.capture import SceneCache
    from addon.engine.methods import direct

    scenes.build("cornell-point")
    scene = SceneCache().update(bpy.context.evaluated_depsgraph_get(), 32, 32)
    monkeypatch.setattr(direct, "RSM_KEEP_BYTES", 1)
    method = _method(gl, "lpv")
    method.set_scene(scene)
    method.compute()
    method.compute()
    assert method.solves == 2
    monkeypatch.undo()
    _assert_same(method.read(), _fresh_images(gl, "lpv", scene))


@pytest.fixture(scope="module")
def sky_scene():
    from addon.bridge import scenes
    from addon.bridge.capture import SceneCache

    scenes.build("window-sky-sun")  # a sun lamp and a sky through a window
    return SceneCache().update(bpy.context.evaluated_depsgraph_get(), 32, 32)


@pytest.mark.parametrize("case", ["lpv", "probes", "probes-2-bounces"])
def test_a_lamp_move_under_a_sky_redraws_none_of_the_skys_work(gl, sky_scene, case):
    # The sky's shadow maps (and the probes' sky light on their atlas) depend on the geometry and the
    # sky's directions, not on the lamps: a lamp's move neither redraws nor re-shades them, and the
    # images are still those of a method set up for the moved lamp.
    method = _method(gl, case)
    method.set_scene(sky_scene)
    first = method.compute()
    assert "sky_shadow" in first
    assert ("probe_sky" in first) == case.startswith("probes")
    lights = _moved_lights(sky_scene.lights, -0.01)
    method.set_lights(lights)
    timings = method.compute(run_gbuffer=False)
    assert method.solves == 2
    assert "sky_shadow" not in timings and "probe_sky" not in timings
    assert ("probe_sky_copy" in timings) == case.startswith("probes")
    _assert_same(method.read(), _fresh_images(gl, case, replace(sky_scene, lights=lights)))
    # A benchmark's full update (run) does every light's work again, the sky's included.
    full = method.run().timings_ms
    assert "sky_shadow" in full
    assert ("probe_sky" in full) == case.startswith("probes")


@pytest.mark.parametrize("case", ["lpv", "probes"])
def test_a_world_change_redraws_the_skys_work(gl, sky_scene, case):
    # Another world: new directions, so their shadow maps are drawn and the probes' sky light shaded
    # again, and the images are those of a method set up under that world.
    method = _method(gl, case)
    method.set_scene(sky_scene)
    method.compute()
    world_map = sky_scene.world_map * np.float32(0.5)
    method.set_world(sky_scene.world_color, world_map)
    timings = method.compute(run_gbuffer=False)
    assert "sky_shadow" in timings
    assert ("probe_sky" in timings) == (case == "probes")
    _assert_same(method.read(), _fresh_images(gl, case, replace(sky_scene, world_map=world_map)))
