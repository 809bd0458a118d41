"""The world as suns (addon/engine/world.py): exact for receivers whose horizon cuts no region."""

import numpy as np
import pytest

from addon.engine.world import constant_map, directions, regions, sky_regions, texel_vectors, world_suns


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


def test_auto_sky_rays_follow_the_worlds_share():
    # RsmConfig.sky_rays = -1 (auto): 8 rays a region where the world gives at least 30 % of the direct
    # light (world_share, as sky_direction_count weighs it), else the filter (0); a number set by hand
    # stays. The world alone: share 1; beside a sun of 3 pi W/m^2, pi / (pi + 3 pi) = 0.25 (filter); of
    # 2 pi, 1 / 3 (rays). The viewport takes the filter for auto and keeps a number set by hand.
    # Bakes trace from 3 %.
    from addon.engine.passes.sky_light import AUTO, AUTO_BAKE_WORLD_SHARE, rays_for, viewport_rays
    from addon.engine.scene import Light
    from addon.engine.world import world_share

    sky = world_suns(constant_map([1.0] * 3), 16)
    strong = Light("SUN", [0, 0, 10], [0, 0, -1], [1, 1, 1], sun_strength=3 * np.pi)
    weaker = Light("SUN", [0, 0, 10], [0, 0, -1], [1, 1, 1], sun_strength=2 * np.pi)
    assert world_share(sky, [], 5.0) == 1.0
    assert np.isclose(world_share(sky, [strong], 5.0), 0.25)
    assert np.isclose(world_share(sky, [weaker], 5.0), 1 / 3)
    assert world_share([], [strong], 5.0) == 0.0
    assert rays_for(AUTO, world_share(sky, [], 5.0)) == 8
    assert rays_for(AUTO, world_share(sky, [weaker], 5.0)) == 8
    assert rays_for(AUTO, world_share(sky, [strong], 5.0)) == 0
    assert rays_for(AUTO, 0.0) == 0
    assert rays_for(0, 1.0) == 0 and rays_for(5, 0.0) == 5  # set by hand: kept, whatever the share
    assert viewport_rays(AUTO) == 0 and viewport_rays(8) == 8 and viewport_rays(0) == 0
    # A bake's texels: rays from AUTO_BAKE_WORLD_SHARE (3 %) on.
    assert rays_for(AUTO, 0.25, AUTO_BAKE_WORLD_SHARE) == 8 and rays_for(AUTO, 0.03, AUTO_BAKE_WORLD_SHARE) == 8
    assert rays_for(AUTO, 0.029, AUTO_BAKE_WORLD_SHARE) == 0 and rays_for(0, 1.0, AUTO_BAKE_WORLD_SHARE) == 0


def test_downsample_keeps_each_texels_light():
    # A texel of the coarse map is its fine texels' mean by solid angle, so int L dw over it is the
    # fine texels' sum (to fp64 rounding), and a uniform map stays uniform.
    from addon.engine.world import downsample

    rng = np.random.default_rng(3)
    fine = rng.random((32, 64, 3))
    coarse = downsample(fine, 4)
    assert coarse.shape == (8, 16, 3)
    _, fine_omega = directions(32, 64)
    _, coarse_omega = directions(8, 16)
    per_texel = (fine * fine_omega[..., None]).reshape(8, 4, 16, 4, 3).sum(axis=(1, 3))
    np.testing.assert_allclose(coarse * coarse_omega[..., None], per_texel, rtol=1e-12)
    np.testing.assert_allclose(downsample(constant_map([0.5, 1.0, 2.0], 32, 64), 8),
                               constant_map([0.5, 1.0, 2.0], 4, 8), rtol=1e-12)
    with pytest.raises(ValueError):
        downsample(fine, 5)


def test_sky_directions_least_is_a_quarter_of_the_most_within_a_draw_budget():
    from addon.engine.methods.direct import SKY_LEAST_TRIANGLE_DRAWS, sky_directions_least

    assert sky_directions_least(100, 256) == 64  # the camera's default: a quarter of 256
    assert sky_directions_least(100, 64) == 16  # the probes' atlas: a quarter of 64
    assert sky_directions_least(SKY_LEAST_TRIANGLE_DRAWS // 32, 256) == 32  # 64 draws would pass the budget
    assert sky_directions_least(67_405, 256) == 16  # Sponza: never below 16
    assert sky_directions_least(100, 8) == 8  # never more than the most


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


def test_the_sky_atlas_keeps_within_its_widest_side():
    # SkyLayout.of: tiles of the asked texels rounded up to whole blocks, unless the near-square atlas
    # would pass ATLAS_MAX_TEXELS (2048) a side: 189 directions take 14 columns, so at most
    # 2048 // 14 = 146 -> 144 texels (whole blocks of 8). The default 64 texels fit 1024 directions.
    from addon.engine.passes.sky_light import ATLAS_MAX_TEXELS, SkyLayout

    assert SkyLayout.of(189, 64).tile_texels == 64
    assert SkyLayout.of(189, 60).tile_texels == 64
    assert SkyLayout.of(189, 1024).tile_texels == 144
    assert SkyLayout.of(1024, 64).tile_texels == 64
    for count in (1, 2, 17, 189, 256, 1024):
        for texels in (16, 64, 300, 1024):
            assert max(SkyLayout.of(count, texels).size) <= ATLAS_MAX_TEXELS


def test_sky_regions_rays_split_each_region_by_its_light():
    # A map with one bright texel: the region holding it gets rays whose shares follow power, each ray a
    # unit vector within its region, the shares summing to 1; one ray per region is the region's own
    # direction (its sun's); no rays: an empty (suns, 0, 4).
    radiance = constant_map(np.array([1.0, 1.0, 1.0]), 16, 32)
    radiance[3, 5] = 50.0
    suns, rays = sky_regions(radiance, 8, 8)
    assert rays.shape == (len(suns), 8, 4)
    np.testing.assert_allclose(rays[..., 3].sum(axis=1), 1.0, rtol=1e-12)
    used = rays[..., 3] > 0
    np.testing.assert_allclose(np.linalg.norm(rays[used][:, :3], axis=1), 1.0, rtol=1e-12)
    for sun, own in zip(suns, rays, strict=True):  # every ray within 90 degrees of its region's direction
        assert np.all(own[own[:, 3] > 0, :3] @ -sun.direction > 0)
    suns1, one = sky_regions(radiance, 8, 1)
    np.testing.assert_allclose(one[:, 0, :3], [-s.direction for s in suns1], atol=1e-12)
    np.testing.assert_allclose(one[:, 0, 3], 1.0)
    assert sky_regions(radiance, 8, 0)[1].shape == (len(suns), 0, 4)
    assert [s.sun_strength for s in suns] == [s.sun_strength for s in world_suns(radiance, 8, by_width=True)]
