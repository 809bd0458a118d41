"""Progressive refinement (DirectMethod.refine): more gathers averaged, less noise, the same images for
the same seed; the denoise filter keeps a flat field flat (tests/gpu/test_denoise.py holds the filter)."""

from dataclasses import replace

import numpy as np
import pytest

pytestmark = [pytest.mark.blender, pytest.mark.gpu]
bpy = pytest.importorskip("bpy")


@pytest.fixture(scope="module")
def cornell_scene():
    from addon.bridge import scenes
    from addon.bridge.capture import SceneCache

    scenes.build("cornell")
    return SceneCache().update(bpy.context.evaluated_depsgraph_get(), 48, 48)


def _images(gl, scene, method, seed, samples, denoise=False):
    from addon.engine import methods
    from addon.engine.config import GIConfig, RsmConfig, VctConfig

    m = methods.create(gl, {"gi": GIConfig(method=method, resolution=48, seed=seed, denoise=denoise),
                            "rsm": RsmConfig(resolution=64, vpl_samples=16),
                            "vct": VctConfig(voxel_cells=16, diffuse_cones=6)})
    m.set_scene(scene)
    m.compute()
    for _ in range(samples - 1):
        m.refine()
    assert m.samples == samples
    return m.read()


def _noise(a, b):
    geometry = a["albedo"][..., 3] > 0
    x, y = a["indirect"][..., :3][geometry], b["indirect"][..., :3][geometry]
    return float(np.sqrt(np.mean((x - y) ** 2)) / np.mean(y))


@pytest.mark.parametrize("method", ["rsm", "vct"])
def test_noise_falls_with_the_samples(gl, cornell_scene, method):
    # Noise = rel_rmse between two seeds. n independent gathers averaged: noise / sqrt(n), so 16 samples
    # leave a quarter; allowed up to 0.35 of it (the seeds of one light's faces are correlated within a
    # sample, and 48 px is few pixels to measure on).
    one = _noise(*(_images(gl, cornell_scene, method, s, 1) for s in (0, 1)))
    sixteen = _noise(*(_images(gl, cornell_scene, method, s, 16) for s in (0, 1)))
    assert one > 0.05, one  # there is noise to reduce: the raw gather at 16 VPLs / 6 cones
    assert sixteen < 0.35 * one, (one, sixteen)


@pytest.mark.parametrize("method", ["rsm", "vct"])
def test_same_seed_same_image(gl, cornell_scene, method):
    a = _images(gl, cornell_scene, method, 3, 4, denoise=True)
    b = _images(gl, cornell_scene, method, 3, 4, denoise=True)
    for key in a:
        np.testing.assert_array_equal(a[key], b[key], err_msg=key)


def test_refining_keeps_the_mean(gl, cornell_scene):
    # The average of 8 gathers estimates the same light as one: means within 3 % (each gather is unbiased
    # for the same integral; 3 %: the one-gather mean's own noise over 48 px).
    one = _images(gl, cornell_scene, "rsm", 0, 1)["indirect"][..., :3].mean()
    eight = _images(gl, cornell_scene, "rsm", 0, 8)["indirect"][..., :3].mean()
    assert eight == pytest.approx(one, rel=0.03)


def test_deterministic_methods_do_not_refine(gl, cornell_scene):
    from addon.engine import methods
    from addon.engine.config import GIConfig, LpvConfig

    m = methods.create(gl, {"gi": GIConfig(method="lpv", resolution=32), "lpv": LpvConfig(grid_cells=16)})
    m.set_scene(cornell_scene)
    m.compute()
    m.refine()
    assert m.samples == 1
    m.set_lights([replace(cornell_scene.lights[0], power_w=1.0)])
    m.refine()
    assert m.samples == 1  # the lights changed: a gather alone would not be the new light
