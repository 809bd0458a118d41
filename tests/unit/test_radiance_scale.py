"""vct_pyramid.radiance_scale: the factor that keeps the half-float pyramid in range (exact arithmetic)."""

import math

import numpy as np
import pytest

from addon.engine.passes.vct_pyramid import HALF_BOUND, light_power_bound_w, radiance_scale
from addon.engine.scene import Light

BOUNDS = (np.array([0.0, 0.0, 0.0]), np.array([2.0, 3.0, 6.0]))  # diagonal 7 m


def lamp(kind, **kw):
    return Light(kind, [1.0, 1.0, 1.0], [0.0, 0.0, -1.0], kw.pop("color", [1.0, 0.5, 0.25]), **kw)


def test_power_bounds_by_kind():
    # Point, spot, area: power_w x the brightest channel. Sun: strength x the bounds' diagonal squared
    # (49 m^2 here; its RSM window is the bounds' projection, never wider than the diagonal either way).
    assert light_power_bound_w(lamp("POINT", power_w=100.0), BOUNDS) == 100.0
    assert light_power_bound_w(lamp("SPOT", power_w=40.0, color=[0.2, 0.8, 0.1]), BOUNDS) == pytest.approx(32.0)
    assert light_power_bound_w(lamp("AREA", power_w=10.0), BOUNDS) == 10.0
    assert light_power_bound_w(lamp("SUN", sun_strength=3.0), BOUNDS) == pytest.approx(147.0)


def test_scale_maps_the_bound_to_half_bound():
    # 100 W + a 3 W/m^2 sun = 247 W; h = 0.1 m; one bounce, albedo <= 1: colour <= 247 / (pi 0.01).
    lights = [lamp("POINT", power_w=100.0), lamp("SUN", sun_strength=3.0)]
    bound = 247.0 / (math.pi * 0.01)
    assert radiance_scale(lights, BOUNDS, 0.1, 1, 0.8) == pytest.approx(HALF_BOUND / bound, rel=1e-12)
    # Bounces: a + a^2 + a^3 with a = max(1, albedo) (an albedo above 1 amplifies each bounce).
    assert radiance_scale(lights, BOUNDS, 0.1, 3, 0.5) == pytest.approx(HALF_BOUND / (3 * bound), rel=1e-12)
    assert radiance_scale(lights, BOUNDS, 0.1, 2, 2.0) == pytest.approx(HALF_BOUND / (6 * bound), rel=1e-12)


def test_scale_is_inverse_in_power_so_stored_values_do_not_depend_on_it():
    # Output linear in power needs the stored (scaled) pyramid to be the same at every power.
    one = radiance_scale([lamp("POINT", power_w=1.0)], BOUNDS, 0.05, 1, 1.0)
    big = radiance_scale([lamp("POINT", power_w=1e9)], BOUNDS, 0.05, 1, 1.0)
    assert one / big == pytest.approx(1e9, rel=1e-12)


def test_no_light_or_a_black_light_leaves_the_scale_at_one():
    assert radiance_scale([], BOUNDS, 0.1, 1, 1.0) == 1.0
    assert radiance_scale([lamp("POINT", power_w=50.0, color=[0.0, 0.0, 0.0])], BOUNDS, 0.1, 1, 1.0) == 1.0
