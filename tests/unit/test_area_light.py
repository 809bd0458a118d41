"""Area emitters with their shape (addon/engine/area_light.py): the polygon irradiance against closed
forms and numerical integration, the patches of an area light, the emitter table."""

import numpy as np
import pytest

from addon.engine.area_light import (
    ELLIPSE_SIDES,
    MAX_VERTICES,
    Emitter,
    emitter_radius_m,
    emitter_table,
    outline,
    polygon_irradiance,
    split_area_light,
)
from addon.engine.scene import Light

UP = np.array([0.0, 0.0, 1.0])


def square(half_m: float, z_m: float) -> np.ndarray:
    return np.array([[-half_m, -half_m, z_m], [half_m, -half_m, z_m], [half_m, half_m, z_m], [-half_m, half_m, z_m]])


def numeric_irradiance(p, n, vertices, samples_per_side=400):
    """E / L by midpoint quadrature over a planar quad (parallelogram v0, v1, v3): sum cos cos' / r^2 dA."""
    v0, v1, v3 = vertices[0], vertices[1], vertices[3]
    u, w = v1 - v0, v3 - v0
    normal = np.cross(u, w)
    area = np.linalg.norm(normal)
    normal /= area
    t = (np.arange(samples_per_side) + 0.5) / samples_per_side
    pts = v0 + t[:, None, None] * u + t[None, :, None] * w
    d = pts - p
    r2 = (d**2).sum(-1)
    cos_r = np.maximum((d @ n) / np.sqrt(r2), 0.0)
    cos_e = np.abs(d @ normal) / np.sqrt(r2)
    return float((cos_r * cos_e / r2).sum() * area / samples_per_side**2)


def test_square_above_a_point_closed_form():
    # A square of side 2a centred h above p, facing it: E / L = 4 * [a / sqrt(a^2 + h^2)] * atan(a / sqrt(a^2 + h^2))
    # (the corner-rectangle form factor summed over four quadrants, times pi).
    a, h = 0.5, 1.0
    s = a / np.sqrt(a * a + h * h)
    expected = 4.0 * s * np.arctan(s)
    assert polygon_irradiance(np.zeros(3), UP, square(a, h)) == pytest.approx(expected, rel=1e-12)


def test_large_polygon_covering_the_hemisphere_gives_pi():
    # A uniform emitter over the whole hemisphere: E = pi L (the limit of a huge square close above).
    assert polygon_irradiance(np.zeros(3), UP, square(1e6, 1.0)) == pytest.approx(np.pi, rel=1e-5)


@pytest.mark.parametrize("p, n", [((0.3, -0.2, 0.0), (0.0, 0.0, 1.0)), ((0.0, 0.0, 0.0), (0.6, 0.0, 0.8)),
                                  ((2.0, 0.0, 0.5), (-1.0, 0.0, 0.0))])
def test_tilted_and_offset_receivers_match_quadrature(p, n):
    # Includes a receiver whose horizon cuts the polygon (the clipped part must not count negatively).
    p, n = np.asarray(p, float), np.asarray(n, float) / np.linalg.norm(n)
    quad = square(0.5, 1.0)
    assert polygon_irradiance(p, n, quad) == pytest.approx(numeric_irradiance(p, n, quad), rel=2e-4)


def test_polygon_behind_the_horizon_gives_zero_and_winding_does_not_matter():
    assert polygon_irradiance(np.zeros(3), -UP, square(0.5, 1.0)) == 0.0
    quad = square(0.5, 1.0)
    assert polygon_irradiance(np.zeros(3), UP, quad[::-1]) == polygon_irradiance(np.zeros(3), UP, quad)


def _area_light(shape="SQUARE", sx=1.0, sy=1.0, power_w=100.0):
    return Light("AREA", [0.0, 0.0, 2.0], [0.0, 0.0, -1.0], [1.0, 0.5, 0.25], power_w=power_w, area_shape=shape,
                 size_x_m=sx, size_y_m=sy, axis_x=[1.0, 0.0, 0.0])


@pytest.mark.parametrize("shape, sx, sy", [("SQUARE", 1.0, 1.0), ("RECTANGLE", 2.0, 0.5), ("DISK", 1.0, 1.0),
                                           ("ELLIPSE", 1.5, 0.5)])
@pytest.mark.parametrize("per_side", [1, 2, 3])
def test_patches_keep_power_and_irradiance(shape, sx, sy, per_side):
    light = _area_light(shape, sx, sy)
    patches = split_area_light(light, per_side)
    # Power split by area, exactly.
    assert sum(pt.power_w for pt in patches) == pytest.approx(light.power_w, rel=1e-12)
    # The patches' polygons together are the light's outline: the irradiance below it is the same as
    # of the whole outline (Lambert's formula is additive over a partition).
    whole = outline(shape, sx, sy)
    whole3 = np.c_[whole, np.full(len(whole), 2.0)]
    p = np.array([0.3, 0.1, 0.0])
    radiance = light.power_w / (np.pi * _area(whole))
    total = sum(r[0] * polygon_irradiance(p, UP, v[:c]) for pt in patches
                for v, c, r in zip(pt.emitter.vertices, pt.emitter.counts, pt.emitter.radiance, strict=True))
    assert total == pytest.approx(radiance * polygon_irradiance(p, UP, whole3), rel=1e-9)
    assert all(pt.emitter.counts.max() <= MAX_VERTICES for pt in patches)


def _area(poly2):
    x, y = poly2[:, 0], poly2[:, 1]
    return 0.5 * abs(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1)))


def test_ellipse_outline_has_the_ellipse_area():
    assert _area(outline("ELLIPSE", 2.0, 1.0)) == pytest.approx(np.pi * 1.0 * 0.5, rel=1e-12)
    assert len(outline("DISK", 1.0, 1.0)) == ELLIPSE_SIDES


def test_patches_emit_towards_the_light_front_only():
    (patch,) = split_area_light(_area_light(), 1)
    v = patch.emitter.vertices[0]
    winding_normal = np.cross(v[1] - v[0], v[2] - v[0])
    assert winding_normal @ patch.direction > 0 and patch.emitter.sided[0] == 1.0


def test_zero_size_light_stays_a_point():
    light = _area_light(sx=0.0, sy=0.0)
    assert split_area_light(light, 2) == [light]


def test_emitter_table_layout():
    lights = [Light("POINT", [0, 0, 0], [0, 0, -1], [1, 1, 1], power_w=1.0), *split_area_light(_area_light(), 2)]
    table, ranges = emitter_table(lights)
    assert ranges[0] == (0, 0) and [r[1] for r in ranges[1:]] == [1, 1, 1, 1]
    assert [r[0] for r in ranges[1:]] == [0, 1, 2, 3]
    assert table.shape == (4, MAX_VERTICES + 1, 4) and table.dtype == np.float32
    assert np.all(table[:, 0, 3] == 4)  # quads
    np.testing.assert_allclose(table[0, MAX_VERTICES, :3], [1.0, 0.5, 0.25] * np.array(100.0 / np.pi), rtol=1e-6)


def test_an_emitters_radius_is_the_disc_of_its_area():
    # The soft shadows' disc: a 1 m x 0.5 m light's two patches' area (0.5 m^2) over pi, rooted; a closed
    # emitter (an octahedron of unit circumradius, area 4 sqrt(3)) the disc of a quarter of its area.
    light = Light("AREA", [0, 0, 2], [0, 0, -1], [1, 1, 1], power_w=10.0, area_shape="RECTANGLE", size_x_m=1.0,
                  size_y_m=0.5, axis_x=[1, 0, 0])
    left = split_area_light(light, 2)[0]
    assert emitter_radius_m(left.emitter, closed=False) == pytest.approx(np.sqrt(0.125 / np.pi), rel=1e-12)
    corners = np.array([[1, 0, 0], [0, 1, 0], [-1, 0, 0], [0, -1, 0]], np.float64)
    tris = [[corners[i], corners[(i + 1) % 4], np.array([0, 0, s])] for s in (1.0, -1.0) for i in range(4)]
    verts = np.array([[*t, t[2]] for t in tris])
    octahedron = Emitter(verts, np.full(8, 3), np.ones((8, 3)))
    assert emitter_radius_m(octahedron, closed=True) == pytest.approx(np.sqrt(4 * np.sqrt(3) / (4 * np.pi)), rel=1e-12)
