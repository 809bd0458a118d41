"""Only what the scene needs: light_views.reaches decides which lights get light views at all, and
views_for spends a light's views on the bounds."""

import numpy as np
import pytest

from addon.engine.passes.light_views import (
    MIN_VIEW_TEXELS,
    bounds_cone,
    face_meets,
    reaches,
    texel_width_m,
    view_texels,
    views_for,
)
from addon.engine.scene import Light
from addon.engine.transforms import box_corners

BOUNDS = (np.array([-1.0, -1.0, 0.0]), np.array([1.0, 1.0, 2.0]))  # sphere: centre (0, 0, 1), radius sqrt(3)


def spot(position, direction, size_deg=45.0, power=100.0):
    return Light("SPOT", np.array(position, float), np.array(direction, float), np.ones(3), power_w=power,
                 spot_size_rad=np.radians(size_deg))


def test_a_spot_reaches_when_its_cone_meets_the_bounds_sphere():
    assert reaches(spot((0, 0, 5), (0, 0, -1)), BOUNDS)
    assert not reaches(spot((0, 0, 5), (0, 0, 1)), BOUNDS)  # pointing away
    # 10 m to the side, aimed 90 degrees off the centre: the sphere spans asin(sqrt(3) / 10) = 10 degrees
    # around the centre's direction, the cone 22.5 degrees around its axis: they do not meet; aimed at
    # the centre they do.
    assert not reaches(spot((10, 0, 1), (0, 1, 0)), BOUNDS)
    assert reaches(spot((10, 0, 1), (-1, 0, 0)), BOUNDS)
    # inside the sphere a spot always counts, whatever its aim
    assert reaches(spot((0, 0, 1), (0, 0, 1)), BOUNDS)


def test_a_cone_just_grazing_the_sphere_counts():
    # Centre 45 degrees off the axis, the sphere's half-angle asin(sqrt(3) / 5) = 20.3 degrees: a cone of
    # half-angle 25 degrees reaches (45 - 20.3 < 25), one of 24 does not.
    d = np.array([1.0, 0.0, 0.0])
    pos = np.array([0.0, 0.0, 1.0]) - 5.0 * np.array([np.cos(np.pi / 4), np.sin(np.pi / 4), 0.0])
    assert reaches(spot(pos, d, size_deg=2 * 25.0), BOUNDS)
    assert not reaches(spot(pos, d, size_deg=2 * 24.0), BOUNDS)


def test_an_area_light_reaches_what_lies_in_front_of_it():
    area = Light("AREA", np.array([0.0, 0.0, 3.0]), np.array([0.0, 0.0, -1.0]), np.ones(3), power_w=50.0,
                 size_x_m=1.0, size_y_m=1.0)
    assert reaches(area, BOUNDS)
    assert not reaches(Light(**{**area.__dict__, "direction": np.array([0.0, 0.0, 1.0])}), BOUNDS)


@pytest.mark.parametrize("light", [
    spot((0, 0, 5), (0, 0, -1), power=0.0),
    Light("SUN", np.zeros(3), np.array([0.0, 0.0, -1.0]), np.ones(3), sun_strength=0.0),
    Light("POINT", np.zeros(3), np.array([0.0, 0.0, -1.0]), np.zeros(3), power_w=10.0),
])
def test_a_light_that_emits_nothing_reaches_nothing(light):
    assert not reaches(light, BOUNDS)


def test_points_and_suns_that_emit_reach():
    assert reaches(Light("POINT", np.array([0.0, 0.0, 50.0]), np.array([0.0, 0.0, -1.0]), np.ones(3), power_w=1.0),
                   BOUNDS)
    assert reaches(Light("SUN", np.zeros(3), np.array([0.0, 0.0, 1.0]), np.ones(3), sun_strength=1.0), BOUNDS)


# -- a light's views spend their texels on the bounds (light_views.views_for) ---------------------------

def lamp(position, kind="POINT", direction=(0, 0, -1), **kw):
    return Light(kind, np.array(position, float), np.array(direction, float), np.ones(3), power_w=100.0, **kw)


def points_in(bounds, n=4000, seed=0):
    lo, hi = bounds
    return lo + np.random.default_rng(seed).random((n, 3)) * (hi - lo)


def in_view(view, points):
    """(n,) bool: which world points the view's frustum holds (w > 0, |x|, |y| <= w in clip space)."""
    clip = np.c_[points, np.ones(len(points))] @ view.view_projection.T
    return (clip[:, 3] > 0) & np.all(np.abs(clip[:, :2]) <= clip[:, 3:4], axis=1)


def test_a_lamp_among_the_geometry_keeps_six_faces():
    views = views_for(lamp((0.2, -0.3, 1.0)), 0, BOUNDS, 256)
    assert [v.face_index for v in views] == [0, 1, 2, 3, 4, 5]


@pytest.mark.parametrize("position", [(0, 0, 30), (25, 10, 1), (-6, 0, -4)])
def test_a_far_lamp_gets_one_view_fitted_to_the_bounds(position):
    # The 2 x 2 x 2 m bounds seen from 30 m span about 5.4 degrees: a cube face would give them a few
    # per cent of its texels; the fitted view holds every point of them (and the widened margin) in a
    # frustum far narrower than a face.
    (view,) = views_for(lamp(position), 0, BOUNDS, 256)
    assert view.face_index == -1
    lo, hi = BOUNDS
    assert in_view(view, points_in((lo - 0.05, hi + 0.05))).all()
    distance = np.linalg.norm(np.array(position, float) - (lo + hi) / 2)
    assert fov_deg(view) < np.degrees(2 * np.arcsin(np.sqrt(3) * 1.2 / distance))  # the bounds' sphere, 20 % wider


def test_a_lamp_just_outside_a_wall_skips_the_faces_that_see_nothing():
    # 0.5 m beyond the face x = 1 the bounds span 140 degrees, too wide for one view: cube faces remain
    # (the bounds widened by 12 texels of 256 at the far distance, 0.27 m, still exclude the lamp); the +x face
    # looks away from them and is skipped, and every point of the bounds lies in a face that is kept
    # (the face a direct-light lookup picks for it, the major axis of its direction).
    position = np.array([1.5, 0.0, 1.0])
    views = views_for(lamp(position), 0, BOUNDS, 256)
    kept = {v.face_index for v in views}
    assert kept == {1, 2, 3, 4, 5}
    d = points_in(BOUNDS) - position
    major = np.argmax(np.abs(d), axis=1)
    face = 2 * major + (d[np.arange(len(d)), major] < 0)
    assert set(face.tolist()) <= kept


def fov_deg(view):
    return np.degrees(2 * np.arctan(np.sqrt(view.texel_scale) * view.resolution / 2))


def test_a_spot_keeps_its_own_cone_where_it_is_the_narrower():
    spot_view = views_for(spot((0, 0, 30), (0, 0, -1), size_deg=3.0), 0, BOUNDS, 256)[0]
    assert fov_deg(spot_view) == pytest.approx(3.06)
    wide_view = views_for(spot((0, 0, 30), (0, 0, -1), size_deg=100.0), 0, BOUNDS, 256)[0]
    assert fov_deg(wide_view) < 10.0


def test_the_bounds_cone_and_the_face_test_are_exact_on_simple_boxes():
    corners = box_corners(np.array([-1.0, -1.0, 4.0]), np.array([1.0, 1.0, 6.0]))
    axis, half = bounds_cone(corners)
    np.testing.assert_allclose(axis, [0, 0, 1])
    assert half == pytest.approx(np.arctan(1 / 4))  # a square view: the near corners (+-1, +-1, 4) on its edges
    assert bounds_cone(corners - np.array([0.0, 0.0, 5.0])) is None  # the origin inside the box
    assert face_meets(np.array([0.0, 0.0, 1.0]), corners)
    assert not face_meets(np.array([0.0, 0.0, -1.0]), corners)
    assert not face_meets(np.array([1.0, 0.0, 0.0]), corners)  # x <= 1 < z everywhere in the box


# -- a view's texels from its footprint (light_views.view_texels) -------------------------------------

def test_view_texels_halve_while_they_still_cover_the_footprint():
    # At 1 cm texels and at most 256 a side: a 2.56 m footprint needs all 256; 1.28 m exactly 128; 1.27 m
    # still 128 (64 would cover 0.64 m); 0.5 m stops at the floor of 64. An odd most (75 = 300 / 4) is
    # never halved into a fraction of a texel, and a most below the floor stays.
    assert view_texels(2.56, 0.01, 256) == 256
    assert view_texels(1.28, 0.01, 256) == 128
    assert view_texels(1.27, 0.01, 256) == 128
    assert view_texels(0.5, 0.01, 256) == MIN_VIEW_TEXELS == 64
    assert view_texels(1.0, 0.01, 300) == 150
    assert view_texels(0.1, 0.01, 300) == 75
    assert view_texels(0.01, 0.01, 32) == 32


def test_a_lamp_under_the_ceiling_draws_its_upward_face_coarse_at_the_same_texel_width():
    # 5 cm under the 2 m ceiling of the 2 x 2 x 2 m bounds (diagonal 2 sqrt(3) = 3.46 m: texels of 13.5 mm
    # at 256): the upward face's footprint at the ceiling is 2 x 0.05 m = 0.1 m, 64 texels (the floor);
    # the downward face's, 2 x 1.95 m = 3.9 m, needs all 256; the side faces' (1 m to the walls: 2 m)
    # 256 too (128 texels would cover only 1.73 m).
    views = views_for(lamp((0.0, 0.0, 1.95)), 0, BOUNDS, 256)
    texels = {v.face_index: v.resolution for v in views}
    assert texels == {0: 256, 1: 256, 2: 256, 3: 256, 4: 64, 5: 256}
    # The coarse face's texels at its geometry (0.05 m x 2 / 64 = 1.6 mm) are no wider than a 256-texel
    # view's across the diagonal: fewer texels, no coarser than the scene's widest view.
    width_m = texel_width_m(BOUNDS, 256)
    assert width_m == pytest.approx(2 * np.sqrt(3) / 256)
    (up,) = (v for v in views if v.face_index == 4)
    assert np.sqrt(up.texel_scale) * 0.05 == pytest.approx(0.1 / 64)


def test_a_narrow_spot_gets_the_texels_its_cone_needs():
    # A 30-degree spot 2 m above the floor it lights, inside the bounds: its cone is 2 tan(15 deg) x 2 m
    # = 1.07 m wide at the floor, 80 texels of 13.5 mm: 128 (a halving of 256 that still covers it;
    # 64 would not). Its texels there are 8.4 mm wide, at most the diagonal view's 13.5 mm.
    (view,) = views_for(spot((0, 0, 2.0), (0, 0, -1), size_deg=30.0), 0, BOUNDS, 256)
    assert view.resolution == 128
    assert np.sqrt(view.texel_scale) * 2.0 <= texel_width_m(BOUNDS, 256)


def test_a_sun_keeps_the_resolution():
    # a sun's view is fitted to the bounds: its footprint is the scene's (and the sky's tiles rely on it)
    sun = Light("SUN", np.zeros(3), np.array([0.3, 0.2, -1.0]) / np.linalg.norm([0.3, 0.2, -1.0]), np.ones(3),
                sun_strength=3.0)
    assert [v.resolution for v in views_for(sun, 0, BOUNDS, 256)] == [256]
