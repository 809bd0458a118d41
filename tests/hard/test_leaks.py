"""Hard case 4: light leaks through a thin shared wall and out of a closed box. Every shipped method."""

from __future__ import annotations

import numpy as np
import pytest
from hard_scenes import assert_sane, box, camera, methods_with_known_leaks, parts, point, rect, render
from hard_scenes import scene as make_scene

pytestmark = pytest.mark.gpu


def _two_rooms():
    # Room A = [-2, 0] x [-1, 1] x [0, 2] (lit, light at (-1, 0, 1)), room B = [0, 2] x ... (dark); they
    # share ONE zero-thickness wall x = 0 (a single quad, two-sided as in Cycles). Both rooms closed.
    a = box([-2, -1, 0], [0, 1, 2])
    b = box([0, -1, 0], [2, 1, 2])
    keep_a = np.r_[0:10]           # drop A's x = hi wall (triangles 10, 11): the shared wall stands in
    keep_b = np.r_[0:8, 10:12]     # drop B's x = lo wall (triangles 8, 9)
    shared = rect([0, -1, 0], [0, 2, 0], [0, 0, 2])
    return parts((a[0][keep_a], a[1][keep_a], 0.8), (b[0][keep_b], b[1][keep_b], 0.8), (*shared, 0.8))


@pytest.mark.parametrize("name", methods_with_known_leaks())
def test_thin_wall_between_rooms(gl, figures, name):
    geo = _two_rooms()
    light = point([-1.0, 0.0, 1.0], 100.0)
    lit_room = render(gl, name, make_scene(geo, [light], camera([-0.3, 0.7, 1.6], [-1, -0.6, -0.5], 48)),
                      rsm_res=128, vpl=64)
    dark = render(gl, name, make_scene(geo, [light], camera([1.7, -0.7, 1.6], [-1, 0.6, -0.5], 48)),
                  rsm_res=128, vpl=64)
    assert_sane(lit_room)
    assert_sane(dark)
    lit_mean = float(lit_room["direct"][..., :3].mean())
    assert lit_mean > 0
    # Direct: every point of room B is hidden from the light by the shared wall; the wall's B side faces
    # away from it. Exact answer 0 (a normal-offset or depth bias that pushes a receiver through the wall
    # near its base would show up here).
    # (A 1 cm depth bias let 3 px of B's floor next to the wall through; biases are now per RSM texel.)
    d = dark["direct"][..., 0]
    figure = 0.0
    if "indirect" in dark:
        # Exact answer: 0 too (nothing in B is lit, and one bounce from A's surfaces cannot pass the wall).
        # Bound: <= 1 % of the lit room's mean direct (what a visibility approximation may let through).
        # Measured for rsm without visibility: 0.10 of the lit room's mean.
        figure = float(dark["indirect"][..., :3].mean()) / lit_mean
        figures("thin wall: mean indirect in the dark room / lit room's mean direct", name, figure, "≤ 0.01")
    figures("thin wall: max direct in the dark room", name, d.max(), "= 0")
    assert d.max() == 0.0
    assert figure <= 0.01


@pytest.mark.parametrize("name", methods_with_known_leaks(voxel_reason=(
    "measured indirect outside up to 3e-5 x P/(6 pi), against an "
    "exact 0: 16 cm cells over the 10 m ground, the box's floor 50 cm up; VPLs on the inner floor one cell "
    "above it reach the ground under the box where the march skips the cells next to its ends")))
def test_light_inside_closed_box_stays_inside(gl, figures, name):
    # A closed box [-0.5, 0.5]^2 x [0.5, 1.5] hangs over a 10 x 10 m ground (z = 0); a 100 W light inside.
    # Exact answer outside the box: direct 0 (the box's outer faces face away from the light, the ground
    # is hidden by the box) and indirect 0 (no light leaves the box).
    geo = parts((*box([-0.5, -0.5, 0.5], [0.5, 0.5, 1.5]), 0.8), (*rect([-5, -5, 0], [10, 0, 0], [0, 10, 0]), 0.8))
    sc = make_scene(geo, [point([0.1, 0.0, 1.0], 100.0)], camera([2.5, -2.0, 1.8], [-1, 0.8, -0.6], 48))
    images = render(gl, name, sc, rsm_res=128, vpl=64)
    assert_sane(images)
    assert images["albedo"][..., 3].mean() > 0.5
    # (24 ground pixels near a cube-face diagonal leaked while the face was picked from p instead of the
    # offset point p_test that is looked up; fixed in shade.comp.glsl.)
    d = images["direct"][..., 0]
    figure = 0.0
    if "indirect" in images:
        # Scale of a leak: the mean Diffuse Direct on the box's 6 m^2 inside is P / (6 pi) = 5.3.
        # Measured for rsm without visibility: up to 0.45 x P/(6 pi) (the ground under the box sees the
        # inner faces of the far walls through the box's floor).
        figure = float(images["indirect"][..., :3].max()) / (100.0 / (6 * np.pi))
        figures("light in a closed box: max indirect outside / P/(6π)", name, figure, "= 0")
    figures("light in a closed box: max direct outside", name, d.max(), "= 0")
    assert d.max() == 0.0
    assert figure == 0.0
