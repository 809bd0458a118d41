"""Emissive meshes as lamps (passes/light_views.emissive_lights), against exact fluxes."""

import numpy as np
import pytest

from addon.engine.passes.light_views import disc_view_factor, emissive_lights


def quad(origin, u, v):
    o, u, v = (np.asarray(a, float) for a in (origin, u, v))
    p = [o, o + u, o + u + v, o + v]
    return [[p[0], p[1], p[2]], [p[0], p[2], p[3]]]


def test_flat_panel_is_area_lights_facing_both_ways():
    # A 0.5 x 0.5 m panel of radiance 20 facing -z: each side emits pi L A = pi * 20 * 0.25 W (Cycles'
    # mesh emission is two-sided). Its triangles are larger than a grouping cell (2 m / 8 = 0.25 m), so
    # they are split and the panel becomes 2 x 2 groups, each two AREA lamps (facing -z and +z) of its
    # share, carrying its triangles (Light.emitter) emitting on that side.
    tris = np.array(quad([-0.25, 0.25, 1.98], [0.5, 0, 0], [0, -0.5, 0]))
    emission = np.full((2, 3), 20.0)
    lamps = emissive_lights(tris, emission, scene_extent_m=2.0)
    assert [lamp.kind for lamp in lamps] == ["AREA"] * 8
    for side in (-1.0, 1.0):
        facing = [lamp for lamp in lamps if lamp.direction[2] == pytest.approx(side)]
        assert len(facing) == 4
        assert sum(lamp.power_w for lamp in facing) == pytest.approx(np.pi * 20 * 0.25)
        centre = sum(lamp.position_m * lamp.power_w for lamp in facing) / sum(lamp.power_w for lamp in facing)
        np.testing.assert_allclose(centre, [0, 0, 1.98], atol=1e-12)
        area = 0.0
        for lamp in facing:
            v = lamp.emitter.vertices
            normals = np.cross(v[:, 1] - v[:, 0], v[:, 2] - v[:, 0])
            area += 0.5 * np.linalg.norm(normals, axis=1).sum()
            # Each triangle emits towards the lamp's side: its winding normal times its sidedness.
            assert np.all((normals @ lamp.direction) * lamp.emitter.sided > 0)
        assert area == pytest.approx(0.25)


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


def test_flat_panel_lamps_carry_their_part_as_occluder():
    # Each group blocks what surfaces send back at it: its lamps carry a disc of the group's area (the
    # panel's quarter here).
    tris = np.array(quad([-0.25, 0.25, 1.98], [0.5, 0, 0], [0, -0.5, 0]))
    lamps = emissive_lights(tris, np.full((2, 3), 20.0), scene_extent_m=2.0)
    for lamp in lamps:
        assert lamp.occluder_radius_m == pytest.approx(np.sqrt(0.25 / 4 / np.pi))


@pytest.mark.parametrize("h, a, r", [(0.02, 0.0, 0.28), (0.02, 0.2, 0.28), (0.02, 0.3, 0.28), (0.5, 0.4, 0.3),
                                     (1.0, 0.0, 0.5), (0.1, 1.0, 0.2)])
def test_disc_view_factor_matches_monte_carlo(h, a, r):
    # Cosine-distributed rays from a surface element facing a parallel disc of radius r, h in front of
    # it and a off its axis: the share that hits the disc is the view factor. 4e5 rays: the standard
    # error sqrt(F (1 - F) / N) is below 8e-4, so 4e-3 is five of them.
    rng = np.random.default_rng(5)
    n = 400_000
    u1, u2 = rng.uniform(size=n), rng.uniform(size=n)
    sin_t, cos_t = np.sqrt(u1), np.sqrt(1.0 - u1)
    dx, dy = sin_t * np.cos(2 * np.pi * u2), sin_t * np.sin(2 * np.pi * u2)
    t = h / cos_t
    hit = (a + t * dx) ** 2 + (t * dy) ** 2 <= r * r  # disc centre at (0, 0, h), element at (a, 0, 0)
    assert disc_view_factor(h, a, r) == pytest.approx(hit.mean(), abs=4e-3)


def test_disc_view_factor_limits():
    # On the axis r^2 / (h^2 + r^2); against the disc (h -> 0) 1 inside it and 0 outside.
    assert disc_view_factor(0.3, 0.0, 0.4) == pytest.approx(0.16 / 0.25, rel=1e-12)
    assert disc_view_factor(1e-6, 0.1, 0.4) == pytest.approx(1.0, abs=1e-9)
    assert disc_view_factor(1e-6, 0.5, 0.4) == pytest.approx(0.0, abs=1e-9)
