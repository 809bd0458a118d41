"""The sky's direct light (passes/sky_light.py): every region of the world map a direction with its
own small shadow map, all summed in one pass."""

from __future__ import annotations

import sys
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "hard"))
from hard_scenes import box, camera, parts, rect  # noqa: E402
from hard_scenes import scene as make_scene  # noqa: E402

from addon.engine import methods  # noqa: E402
from addon.engine.config import GIConfig, RsmConfig  # noqa: E402
from addon.engine.world import constant_map  # noqa: E402

pytestmark = pytest.mark.gpu

RADIANCE = np.array([0.5, 1.0, 2.0], np.float32)  # W/m^2/sr per colour


def direct(gl, sc, **rsm) -> np.ndarray:
    """The direct light of `sc` at 32 px; the shadow maps' filter unless `rsm` sets sky_rays (its default,
    auto, takes rays under a world that gives most of the light, as every scene here has)."""
    rsm = {"sky_rays": 0, **rsm}
    method = methods.create(gl, {"gi": GIConfig(method="direct", resolution=32), "rsm": RsmConfig(**rsm)})
    method.set_scene(sc)
    return method.run().images["direct"]


def open_floor():
    geometry = parts((*rect([-2, -2, 0], [4, 0, 0], [0, 4, 0]), 0.5))
    sc = make_scene(geometry, [], camera([0, -0.01, 3], [0, 0.01, -1], size=32, fov_deg=40))
    return replace(sc, world_map=constant_map(RADIANCE))


def closed_box(wall_m: float):
    """A closed 2 m box with walls `wall_m` thick under a sky 1000 times RADIANCE, seen from inside."""
    outer = box([-1 - wall_m, -1 - wall_m, -wall_m], [1 + wall_m, 1 + wall_m, 2 + wall_m], inward=False)
    inner = box([-1, -1, 0], [1, 1, 2], inward=True)
    sc = make_scene(parts((*outer, 0.5), (*inner, 0.5)), [], camera([0.5, 0.5, 1.5], [-1, -1, -0.7], size=32))
    return replace(sc, world_map=constant_map(RADIANCE * 1e3))


@pytest.mark.parametrize(("count", "rtol"), [(16, 0.015), (128, 1e-3)])
def test_open_floor_under_a_uniform_sky_gets_its_radiance(gl, count, rtol):
    # E = pi L on a floor under a uniform sky, so Diffuse Direct = E / pi = L exactly: the regions'
    # vector irradiances sum to it (world.py, exact for a floor: the first split is the horizon) and
    # nothing but the floor itself is there to block. 128 directions: 1e-3 (fp32 sums). 16: a wide
    # region's soft-shadow disc, at a low direction, reaches floor that lies nearer the sky than the
    # receiver; the receiver's plane, extrapolated across the disc for at most 8 texels of depth, keeps
    # it lit: measured exact (1.09 % low with a lift instead of the plane), bounded at 1.5 % as a
    # narrower cap of the plane shadows it (4 texels: more than 1.5 %).
    img = direct(gl, open_floor(), sky_directions=count)
    centre = img[8:24, 8:24, :3].reshape(-1, 3)
    np.testing.assert_allclose(centre, np.broadcast_to(RADIANCE, centre.shape), rtol=rtol)
    assert centre.max() <= RADIANCE.max() * (1 + 1e-3)  # never more than the sky gives


@pytest.mark.parametrize("wall_m", [0.1, 0.4])
def test_closed_box_under_a_sky_stays_dark(gl, wall_m):
    # A closed 2 m box under a bright sky: no direction reaches its inside. Walls 0.4 m thick (about 8
    # texels of a 64-texel tile): exactly 0 (with the receiver's plane extrapolated for 16 texels of depth
    # instead of 8, 0.06 %). Walls 0.1 m (2 texels): a soft-shadow disc at a grazing direction reaches
    # past the roof's silhouette to surfaces deeper than the receiver (one depth layer cannot tell them
    # from the floor seen through an opening); measured 85 of 1024 pixels at most 0.37 % of the open
    # floor's light, 0.008 % on average: bounded at 1 % and 0.03 %.
    img = direct(gl, closed_box(wall_m), sky_texels=64)
    assert np.isfinite(img).all() and img.min() >= 0.0
    share = img[..., :3] / (RADIANCE * 1e3)  # of what the open floor gets
    if wall_m >= 0.4:
        assert share.max() == 0.0
    else:
        assert share.max() < 0.01 and share.mean() < 3e-4


@pytest.mark.parametrize("count", [16, 128])
def test_open_floor_with_exact_rays_gets_its_radiance(gl, count):
    # With RsmConfig.sky_rays nothing is estimated where nothing blocks: the depth bounds show the floor
    # in front of everything, or its rays cross no triangle but its own (which they start off). Exact up
    # to fp32 sums (1e-3, as at 128 directions above), at 16 wide directions too.
    img = direct(gl, open_floor(), sky_directions=count, sky_rays=8)
    centre = img[8:24, 8:24, :3].reshape(-1, 3)
    np.testing.assert_allclose(centre, np.broadcast_to(RADIANCE, centre.shape), rtol=1e-3)


@pytest.mark.parametrize("wall_m", [0.1, 0.4])
def test_closed_box_with_exact_rays_stays_dark(gl, wall_m):
    # Every ray from the inside crosses a wall's triangles: exactly 0, the thin walls too (the filter
    # lets 0.37 % through them at most, above).
    img = direct(gl, closed_box(wall_m), sky_rays=8)
    assert np.isfinite(img).all()
    assert img[..., :3].max() == 0.0


def test_a_skylight_with_exact_rays_lets_in_its_share(gl):
    # A closed 6 m room 1 m high whose flat roof has one square opening of half-side a = 0.5 m above the
    # floor's centre, under a uniform sky: the centre sees the sky through the opening only, so its
    # Diffuse Direct is L times the opening's form factor, exactly. For a parallel rectangle with a corner
    # above the point, F = (X / sqrt(1 + X^2) atan(Y / sqrt(1 + X^2)) + Y / sqrt(1 + Y^2) atan(X / sqrt(1
    # + X^2))) / (2 pi), X, Y its sides over the height; the opening is four such quarters (F = 0.2395,
    # checked against a numerical integral). The rays are a quadrature of the opening: at one point, on
    # a 64 x 128 map, 512 regions of 8 rays read 1.006 F, 128 of 16 0.968, 128 of 8 0.944 (the filter
    # 1.13); bounded at 2 % for 512 of 8.
    a, h, r = 0.5, 1.0, 3.0
    roof = [rect([-r, -r, h], [r - a, 0, 0], [0, 2 * r, 0]), rect([a, -r, h], [r - a, 0, 0], [0, 2 * r, 0]),
            rect([-a, -r, h], [2 * a, 0, 0], [0, r - a, 0]), rect([-a, a, h], [2 * a, 0, 0], [0, r - a, 0])]
    walls = [rect([-r, -r, 0], [2 * r, 0, 0], [0, 0, h]), rect([-r, r, 0], [2 * r, 0, 0], [0, 0, h]),
             rect([-r, -r, 0], [0, 2 * r, 0], [0, 0, h]), rect([r, -r, 0], [0, 2 * r, 0], [0, 0, h])]
    floor = rect([-r, -r, 0], [2 * r, 0, 0], [0, 2 * r, 0])
    sc = make_scene(parts(*[(*piece, 0.5) for piece in (*roof, *walls, floor)]), [],
                    camera([0, -0.01, 0.6], [0, 0.01, -1], size=32, fov_deg=20))
    img = direct(gl, replace(sc, world_map=constant_map(RADIANCE, 64, 128)), sky_directions=512, sky_rays=8)
    x = a / h
    quarter = 2 * x / np.sqrt(1 + x * x) * np.arctan(x / np.sqrt(1 + x * x)) / (2 * np.pi)
    centre = img[14:18, 14:18, :3].reshape(-1, 3)
    np.testing.assert_allclose(centre.mean(axis=0), RADIANCE * 4 * quarter, rtol=0.02)


def test_auto_sky_rays_trace_where_the_world_gives_the_light(gl):
    # RsmConfig's default sky_rays (auto, sky_light.rays_for): under a sky that is all the light, the
    # closed box's thin walls are tested by 8 exact rays a region (exactly 0 inside, where the filter lets
    # up to 0.37 % through: above); with a lamp that gives most of the light, the filter (no rays).
    from addon.engine.scene import Light

    sc = closed_box(0.1)
    method = methods.create(gl, {"gi": GIConfig(method="direct", resolution=32), "rsm": RsmConfig()})
    method.set_scene(sc)
    img = method.run().images["direct"]
    assert method.sky().rays == 8
    assert img[..., :3].max() == 0.0
    lamp = Light("POINT", [0.0, 0.0, 1.0], [0, 0, -1], [1, 1, 1], power_w=1e7)
    method.set_lights([lamp])
    method.run()
    assert method.sky().rays == 0


@pytest.mark.parametrize(("power_w", "rays"), [(1e6, 8), (1e7, 0)])
def test_a_bake_traces_the_skys_rays_from_a_smaller_share(gl, power_w, rays):
    # A bake (bake_raster.TexelBaker sets DirectMethod.baking) takes rays from AUTO_BAKE_WORLD_SHARE
    # (3 %) of the direct light on, a camera from 30 %. The box's sky (1e3 RADIANCE, luminance 966:
    # E = pi L = 3034 W/m^2) beside a lamp of P W at the scene's radius r = 1.905 m (half its bounds'
    # diagonal): P / (4 pi r^2) = 21,900 W/m^2 at 1e6 W, a share of 0.122 (bake: rays; camera: the
    # filter); at 1e7 W 0.0137 (the filter for both).
    from addon.bridge.bake_raster import TexelBaker
    from addon.engine import world
    from addon.engine.scene import Light

    lamp = Light("POINT", [0.0, 0.0, 1.0], [0, 0, -1], [1, 1, 1], power_w=power_w)
    sc = replace(closed_box(0.1), lights=[lamp])
    camera = methods.create(gl, {"gi": GIConfig(method="direct", resolution=32), "rsm": RsmConfig()})
    camera.set_scene(sc)
    lo, hi = camera.bounds_m
    share = world.world_share(camera.world_suns(), [lamp], 0.5 * float(np.linalg.norm(hi - lo)))
    assert share == pytest.approx(0.122 if power_w == 1e6 else 0.0137, rel=0.02)
    assert camera.sky().rays == 0
    bake = methods.create(gl, {"gi": GIConfig(method="direct", resolution=32), "rsm": RsmConfig()})
    bake.set_scene(sc)
    TexelBaker(bake)
    assert bake.baking and bake.sky().rays == rays
