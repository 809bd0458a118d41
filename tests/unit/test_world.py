"""The world as suns (addon/engine/world.py): exact for receivers whose horizon cuts no region."""

import numpy as np
import pytest

from addon.engine.world import constant_map, directions, regions, texel_vectors, world_suns


def irradiance(suns, n):
    """What the direct pass computes from suns, per colour: sum strength x colour x max(0, n . toward)."""
    n = np.asarray(n, float)
    return sum(s.sun_strength * s.color * max(0.0, float(n @ -s.direction)) for s in suns)


def test_solid_angles_and_vectors_are_exact():
    _, omega = directions(16, 32)
    assert omega.sum() == pytest.approx(4 * np.pi, rel=1e-12)
    v = texel_vectors(16, 32)
    assert np.abs(v.sum(axis=(0, 1))).max() < 1e-12  # a whole sphere has no net direction
    assert v[:8, :, 2].sum() == pytest.approx(np.pi, rel=1e-12)  # upper hemisphere: int cos = pi


@pytest.mark.parametrize("count", [2, 8, 32, 64])
def test_uniform_sky_over_a_floor_gives_pi_l(count):
    # E = pi L on a floor and a ceiling, exactly: the first split is the horizon, so no region straddles
    # theirs. A wall's horizon cuts regions: within 10 % of pi L at 8 to 32 suns, 2 % at 64 (1.4 % measured).
    radiance = np.array([0.5, 1.0, 2.0])
    suns = world_suns(constant_map(radiance), count)
    assert len(suns) == count
    np.testing.assert_allclose(irradiance(suns, [0, 0, 1]), np.pi * radiance, rtol=1e-9)
    np.testing.assert_allclose(irradiance(suns, [0, 0, -1]), np.pi * radiance, rtol=1e-9)
    if count >= 8:
        tol = 0.02 if count >= 64 else 0.1
        np.testing.assert_allclose(irradiance(suns, [1, 0, 0]), np.pi * radiance, rtol=tol)


def test_bright_spot_gets_its_own_small_region():
    # A sun disc 1e6 times the rest (an HDRI's sun): power-median splits isolate it, so one sun points
    # at it and carries its light.
    m = constant_map([1e-3] * 3, 32, 64)
    m[8, 40] = 1e3
    dirs, _ = directions(32, 64)
    suns = world_suns(m, 16)
    brightest = max(suns, key=lambda s: s.sun_strength)
    assert float(-brightest.direction @ dirs[8, 40]) > 0.99


def test_black_world_gives_no_suns():
    assert world_suns(constant_map([0.0, 0.0, 0.0]), 16) == []


def test_regions_partition_the_map():
    power = np.random.default_rng(0).uniform(size=(16, 32))
    covered = np.zeros_like(power, int)
    for r in regions(power, 24):
        covered[r] += 1
    assert np.all(covered == 1)


def test_regions_by_width_split_a_dim_wide_ground():
    # A bright sky over a ground 100 times dimmer: split by power alone, the ground stays one region (its
    # power never leads); weighed by angular width as well, it is split too (the shadow of one direction
    # standing in for a region errs by the region's light times its width).
    m = constant_map([1.0] * 3, 32, 64)
    m[16:] = 0.01
    _, omega = directions(32, 64)
    power = m[..., 0] * omega
    below = lambda rects: sum(1 for r in rects if r[0].start >= 16)  # noqa: E731
    assert below(regions(power, 64)) == 1
    assert below(regions(power, 64, omega)) > 1


def test_sky_direction_count_follows_the_worlds_share():
    from addon.engine.scene import Light
    from addon.engine.world import sky_direction_count

    sky = world_suns(constant_map([1.0] * 3), 16)  # a floor under it gets pi W/m^2
    sun = Light("SUN", [0, 0, 10], [0, 0, -1], [1, 1, 1], sun_strength=3 * np.pi)
    assert sky_direction_count(sky, [], 256, 16, 5.0) == 256  # the world is all the light
    assert sky_direction_count(sky, [sun], 256, 16, 5.0) == 64  # a quarter of it: pi / (pi + 3 pi)
    dim = world_suns(constant_map([1e-3] * 3), 16)
    assert sky_direction_count(dim, [sun], 256, 16, 5.0) == 16  # never fewer than `least`
    assert sky_direction_count([], [sun], 256, 16, 5.0) == 0  # no world, no directions


def test_power_shares_split_by_luminance_and_never_divide_by_zero():
    from addon.engine.scene import Light
    from addon.engine.world import power_shares

    def sun(strength, color):
        return Light("SUN", [0, 0, 10], [0, 0, -1], color, sun_strength=strength)

    # Luminance weights (Rec.709): pure green 0.7152, pure blue 0.0722, so green at strength 1 against
    # blue at strength 2 share 0.7152 : 0.1444.
    shares = power_shares([sun(1.0, [0, 1, 0]), sun(2.0, [0, 0, 1])])
    np.testing.assert_allclose(shares, np.array([0.7152, 0.1444]) / 0.8596, rtol=1e-12)
    np.testing.assert_array_equal(power_shares([sun(0.0, [1, 1, 1])] * 4), [0.25] * 4)  # all dark: equal
