"""Emissive meshes as lamps (passes/light_views.emissive_lights), against exact fluxes."""

import numpy as np
import pytest

from addon.engine.passes.light_views import emissive_lights


def quad(origin, u, v):
    o, u, v = (np.asarray(a, float) for a in (origin, u, v))
    p = [o, o + u, o + u + v, o + v]
    return [[p[0], p[1], p[2]], [p[0], p[2], p[3]]]


def test_flat_panel_is_two_area_lights():
    # A 0.5 x 0.5 m panel of radiance 20 facing -z: each side emits pi L A = pi * 20 * 0.25 W (Cycles'
    # mesh emission is two-sided), so two AREA lamps of that power facing -z and +z.
    tris = np.array(quad([-0.25, 0.25, 1.98], [0.5, 0, 0], [0, -0.5, 0]))
    emission = np.full((2, 3), 20.0)
    lamps = emissive_lights(tris, emission, scene_extent_m=2.0)
    assert [lamp.kind for lamp in lamps] == ["AREA", "AREA"]
    for lamp in lamps:
        assert lamp.power_w == pytest.approx(np.pi * 20 * 0.25)
        np.testing.assert_allclose(lamp.position_m, [0, 0, 1.98], atol=1e-12)
    np.testing.assert_allclose(sorted(lamp.direction[2] for lamp in lamps), [-1.0, 1.0])


def test_closed_emitter_is_one_point_light():
    # A closed 0.2 m cube of radiance 5: its outer surface emits pi L A = pi * 5 * 0.24 W; its normals
    # cancel, so one isotropic POINT lamp at its centre (the inside's light stays inside).
    lo, s = np.array([1.0, 2.0, 3.0]), 0.2
    faces = [([0, 0, 0], [s, 0, 0], [0, s, 0]), ([0, 0, s], [0, s, 0], [s, 0, 0]),
             ([0, 0, 0], [0, 0, s], [s, 0, 0]), ([0, s, 0], [s, 0, 0], [0, 0, s]),
             ([0, 0, 0], [0, s, 0], [0, 0, s]), ([s, 0, 0], [0, 0, s], [0, s, 0])]
    tris = np.array([t for o, u, v in faces for t in quad(lo + o, u, v)])
    lamps = emissive_lights(tris, np.full((12, 3), 5.0), scene_extent_m=30.0)
    assert len(lamps) == 1 and lamps[0].kind == "POINT"
    assert lamps[0].power_w == pytest.approx(np.pi * 5 * 6 * s * s)
    np.testing.assert_allclose(lamps[0].position_m, lo + s / 2, atol=1e-12)


def test_no_emission_no_lamps():
    assert emissive_lights(np.zeros((0, 3, 3)), np.zeros((0, 3)), 1.0) == []
