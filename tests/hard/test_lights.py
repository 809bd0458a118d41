"""Hard cases of the lights artists use: a black world, an HDRI whose sun is 1e6 times the rest, an
emitter of zero area, an area light of zero size. Every method: finite, non-negative, and the light it
should give (exact where there is a closed form)."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
from hard_scenes import ALL_METHODS, assert_sane, camera, parts, rect, render
from hard_scenes import scene as make_scene

from addon.engine.scene import Light
from addon.engine.world import constant_map, directions

pytestmark = pytest.mark.gpu


def floor_scene(lights=(), **world):
    geometry = parts((*rect([-2, -2, 0], [4, 0, 0], [0, 4, 0]), 0.5))
    sc = make_scene(geometry, lights, camera([0, -0.01, 3], [0, 0.01, -1], size=32, fov_deg=40))
    return replace(sc, **world)


@pytest.mark.parametrize("name", ALL_METHODS)
def test_black_world_gives_nothing(gl, name):
    images = render(gl, name, floor_scene(world_color=np.zeros(3, np.float32), world_map=constant_map([0, 0, 0])))
    assert_sane(images)
    assert images["direct"][..., :3].max() == 0.0


@pytest.mark.parametrize("name", ALL_METHODS)
def test_hdri_sun_a_million_times_the_sky(gl, name):
    # A sky of radiance 1e-3 with one texel at 1e3 (a sun disc 1e6 times brighter): the floor's direct
    # light is the map's vector irradiance along +z, pi x 1e-3 from the sky plus the sun texel's int
    # w_z dw x 1e3; suns split by power give the sun its own region, so 5 % (the sky's share in the
    # sun's region and its soft shadow on an open floor) bounds the error. Finite and non-negative
    # everywhere, the indirect included.
    sky = constant_map([1e-3] * 3, 32, 64)
    sky[6, 20] = 1e3
    images = render(gl, name, floor_scene(world_map=sky.astype(np.float32)))
    assert_sane(images)
    dirs, omega = directions(32, 64)
    upper = dirs[..., 2] > 0
    expected = float(np.sum((sky[..., 0] * dirs[..., 2] * omega)[upper])) / np.pi  # Diffuse Direct = E / pi
    centre = images["direct"][12:20, 12:20, 0]
    assert centre.mean() == pytest.approx(expected, rel=0.05)


@pytest.mark.parametrize("name", ALL_METHODS)
def test_emitter_of_zero_area_emits_nothing(gl, name):
    floor = parts((*rect([-2, -2, 0], [4, 0, 0], [0, 4, 0]), 0.5))
    flat = np.array([[[0, 0, 1], [1, 0, 1], [2, 0, 1]]], np.float64)  # collinear: zero area
    tris = np.concatenate([floor[0], flat])
    sc = make_scene((tris, np.concatenate([floor[1], np.tile([0, 0, -1], (1, 3, 1))]),
                     np.concatenate([floor[2], [[0.5] * 3]])), [], camera([0, -0.01, 3], [0, 0.01, -1], size=32))
    sc.emission[-1] = 100.0
    images = render(gl, name, sc)
    assert_sane(images)
    assert images["direct"][..., :3].max() == 0.0


@pytest.mark.parametrize("name", ALL_METHODS)
def test_area_light_of_zero_size_is_its_point_limit(gl, name):
    # A 100 W area light of size 0, 1 m above the floor, facing down: a Lambertian point, E = P / pi *
    # cos^2 / r^2 below it (at the floor's centre P / pi W/m^2): Diffuse Direct 100 / pi^2.
    light = Light("AREA", [0, 0, 1], [0, 0, -1], [1, 1, 1], power_w=100.0, size_x_m=0.0, size_y_m=0.0)
    images = render(gl, name, floor_scene([light]))
    assert_sane(images)
    assert images["direct"][15:17, 15:17, 0].mean() == pytest.approx(100.0 / np.pi**2, rel=0.01)
