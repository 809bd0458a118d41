"""tools/window_sky_oracle.py's exact visibility through a window and its direction sampling (docs/DIRECT.md,
"What limits the sky pass")."""

import importlib.util
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
_spec = importlib.util.spec_from_file_location("window_sky_oracle", ROOT / "tools" / "window_sky_oracle.py")
oracle = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(oracle)

# window-room's tunnel: the wall from y = 2 to 2.1, the opening x in [-0.5, 0.5], z in [1, 2].
TUNNEL = (2.0, 2.1, (-0.5, 0.5), (1.0, 2.0))


def test_a_ray_sees_the_sky_only_through_both_ends_of_the_tunnel():
    # From (0, 0, 1.5): straight north passes both ends' centres; 10 degrees up still passes (z = 1.870 at
    # y = 2.1); 20 degrees up leaves the inner end at z = 2.228 (above the opening); east and south never
    # reach the wall. From (0, 1.9, 1.5), 80 degrees to the east of north crosses the inner end at x = 0.567
    # (outside); 70 degrees crosses it at x = 0.275 but the outer end at x = 0.549: the tunnel's side stops it.
    def toward(azimuth_deg, elevation_deg):
        a, e = np.radians(azimuth_deg), np.radians(elevation_deg)
        return np.array([np.cos(e) * np.sin(a), np.cos(e) * np.cos(a), np.sin(e)])

    towards = np.array([toward(0, 0), toward(0, 10), toward(0, 20), toward(90, 0), toward(180, 0)])
    centre = np.array([[0.0, 0.0, 1.5]])
    assert oracle.sees_sky(centre, towards, TUNNEL).tolist() == [[True, True, False, False, False]]
    near = np.array([[0.0, 1.9, 1.5]])
    assert oracle.sees_sky(near, np.array([toward(80, 0), toward(70, 0), toward(60, 0)]),
                           TUNNEL).tolist() == [[False, False, True]]


def test_sub_directions_cover_the_northern_half_with_its_solid_angle():
    # Every direction kept looks north (y > 0). Of the 16 x 4 columns of directions exactly the half whose
    # longitudes lie in (0, pi) are kept (no column's centre lies on y = 0), so their solid angles sum to
    # the half sphere, 2 pi, to rounding. Each maps to the texel it lies in.
    towards, omega, texel = oracle.sub_directions(8, 16)
    assert (towards[:, 1] > 0).all()
    assert np.isclose(omega.sum(), 2 * np.pi, rtol=1e-12)
    rows, cols = texel // 16, texel % 16
    lat = np.arcsin(towards[:, 2])
    lon = np.arctan2(towards[:, 1], towards[:, 0])
    assert (np.floor((np.pi / 2 - lat) / np.pi * 8) == rows).all()
    assert (np.floor((lon + np.pi) / (2 * np.pi) * 16) == cols).all()


def test_leaves_room_per_pixel_matches_the_grid_of_every_direction():
    # leaves_room with one direction per point is the diagonal of sees_sky's points x directions grid.
    rng = np.random.default_rng(3)
    points = np.column_stack([rng.uniform(-1, 1, 200), rng.uniform(0, 1.9, 200), rng.uniform(0.5, 2.5, 200)])
    towards = rng.normal(size=(200, 3))
    towards /= np.linalg.norm(towards, axis=1, keepdims=True)
    grid = oracle.sees_sky(points, towards, TUNNEL)
    assert grid.any() and not grid.all()
    assert (oracle.leaves_room(points, towards, TUNNEL) == np.diag(grid)).all()


def test_jittered_sky_is_unbiased_under_an_open_sky():
    # A map of radiance 1 everywhere, a tunnel so wide that every ray going north leaves, receivers facing
    # north (+y): each sees the whole northern half sphere, E = int L cos dw = pi exactly. Parts: the map's
    # 16 columns of 8 x 16 texels (the southern ones, wholly behind the receivers, add 0 exactly). The
    # estimate per receiver is unbiased; the mean of 20000 independent receivers lies within 5 standard
    # errors of pi (their spread measured, so the bound follows the estimator's own noise).
    radiance = np.ones((8, 16, 3))
    parts = [(slice(0, 8), slice(c, c + 1)) for c in range(16)]
    n = 20000
    points = np.tile([0.0, 0.0, 0.0], (n, 1))
    normals = np.tile([0.0, 1.0, 0.0], (n, 1))
    wide = (1.0, 1.1, (-1e6, 1e6), (-1e6, 1e6))
    e = oracle.jittered_sky(points, normals, radiance, parts, wide, seed=0)[:, 0]
    assert e.std() > 0
    assert abs(e.mean() - np.pi) < 5 * e.std() / np.sqrt(n)
