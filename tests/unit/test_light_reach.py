"""Only what the scene needs: light_views.reaches decides which lights get light views at all."""

import numpy as np
import pytest

from addon.engine.passes.light_views import reaches
from addon.engine.scene import Light

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
