"""The probe grid's numpy reference (addon/engine/probe_grid.py): placement, the faces' frames and
projections, and the closed-form texel solid angles that the SH projection weighs texels by."""

import math

import numpy as np
import pytest

from addon.engine import sh
from addon.engine.probe_grid import (
    FACE_FRAMES,
    RELOCATE_CLEARANCE_RATIO,
    RELOCATE_MAX_OFFSET_RATIO,
    ProbeGrid,
    face_view_projection,
    relocation_step,
    texel_directions,
    texel_solid_angles,
)


@pytest.mark.parametrize("n", [1, 2, 7, 16, 64])
def test_texel_solid_angles_sum_to_the_sphere(n):
    # Six faces partition the sphere: the exact areas sum to 4 pi; float64 rounding of ~6 n^2 atan terms.
    assert 6.0 * texel_solid_angles(n).sum() == pytest.approx(4.0 * math.pi, abs=1e-12)


def test_one_texel_faces_are_a_sixth_of_the_sphere():
    assert texel_solid_angles(1)[0, 0] == pytest.approx(4.0 * math.pi / 6.0, abs=1e-14)


def test_texel_solid_angle_matches_a_fine_subdivision():
    # The corner texel of a 4 x 4 face against 400 x 400 sub-texels of dA cos / r^2 = dA / (1 + x^2 + y^2)^1.5
    # (midpoint rule: error ~1e-6 of the value, bound 1e-5).
    m = 400
    u = -1.0 + (np.arange(m) + 0.5) * (0.5 / m)
    x, y = np.meshgrid(u, u)
    fine = np.sum((0.5 / m) ** 2 / (1.0 + x * x + y * y) ** 1.5)
    assert texel_solid_angles(4)[0, 0] == pytest.approx(fine, rel=1e-5)


def test_frames_are_right_handed_and_partition_by_major_axis():
    for face, (f, r, u) in enumerate(FACE_FRAMES):
        assert np.allclose(np.cross(r, u), f)
        assert np.argmax(np.abs(f)) == face // 2 and (f.sum() < 0) == (face % 2 == 1)
    d = texel_directions(8)
    for face in range(6):
        axis = np.argmax(np.abs(d[face]), axis=-1)
        assert np.all(axis == face // 2)


def test_constant_radiance_projects_to_exact_sh():
    # L = 1 everywhere: c_0 = Y00 * 4 pi = 2 sqrt(pi) exactly (the areas are exact), every other
    # coefficient 0 by the cube's symmetry; float64 sums of 6 n^2 terms: 1e-12.
    n = 16
    dirs = texel_directions(n).reshape(-1, 3)
    weights = np.tile(texel_solid_angles(n).ravel(), 6)
    c = sh.project(np.ones(len(dirs)), dirs, weights, order=2)
    assert c[0] == pytest.approx(2.0 * math.sqrt(math.pi), abs=1e-12)
    assert np.abs(c[1:]).max() < 1e-12


def test_projection_recovers_an_l2_function():
    # L(w) = 1 + w.z + (3 z^2 - 1): its coefficients are exact sums of Y's; texel-centre sampling errs by
    # O(1 / n^2): 3e-3 of the largest coefficient at n = 16 (bound 1e-2).
    n = 16
    dirs = texel_directions(n).reshape(-1, 3)
    weights = np.tile(texel_solid_angles(n).ravel(), 6)
    radiance = 1.0 + dirs[:, 2] + (3.0 * dirs[:, 2] ** 2 - 1.0)
    c = sh.project(radiance, dirs, weights, order=2)
    exact = np.zeros(9)
    exact[0] = 1.0 / sh.Y00
    exact[2] = 1.0 / sh.Y1
    exact[6] = 1.0 / sh.Y2_ZZ
    assert np.abs(c - exact).max() < 1e-2 * np.abs(exact).max()


def test_face_projection_maps_each_texel_direction_to_its_ndc():
    # A point along texel (i, j)'s direction lands at NDC (s, t) of that texel centre, depth inside [-1, 1].
    n, center = 8, np.array([0.3, -1.0, 2.0])
    dirs = texel_directions(n)
    st = 2.0 * (np.arange(n) + 0.5) / n - 1.0
    for face in range(6):
        m = face_view_projection(center, face, 0.01, 100.0)
        p = np.c_[center + 3.0 * dirs[face].reshape(-1, 3), np.ones(n * n)]
        clip = p @ m.T
        ndc = clip[:, :3] / clip[:, 3:]
        t, s = np.meshgrid(st, st, indexing="ij")
        assert np.allclose(ndc[:, 0], s.ravel()) and np.allclose(ndc[:, 1], t.ravel())
        assert np.all(np.abs(ndc[:, 2]) < 1.0)


def test_grid_fits_the_bounds_and_is_flat_for_flat_scenes():
    cube = ProbeGrid.fit(np.zeros(3), np.full(3, 4.0), probes_per_side=8, face_texels=16)
    assert cube.dims == (8, 8, 8) and cube.spacing_m == 0.5
    pos = cube.positions_m()
    assert np.allclose(pos.min(axis=0), 0.25) and np.allclose(pos.max(axis=0), 3.75)  # half a spacing inside
    flat = ProbeGrid.fit(np.zeros(3), np.array([10.0, 5.0, 0.0]), probes_per_side=4, face_texels=16)
    assert flat.dims == (4, 2, 1)
    assert flat.atlas_size[0] % (3 * 16) == 0 and flat.atlas_size[1] % (2 * 16) == 0
    # Every probe's tile lies inside the atlas and no two overlap.
    origins = {flat.face_origin(p, 0) for p in range(flat.count)}
    assert len(origins) == flat.count
    w, h = flat.atlas_size
    assert all(x + 3 * 16 <= w and y + 2 * 16 <= h for x, y in origins)


def test_a_large_scene_gets_fewer_probes_within_the_capture_budget():
    # 1e6 triangles on a 20 m floor: 16 a side would draw 6 x 256 x 1e6 triangles; a budget of 5e7 leaves
    # 2 a side (4 probes: 2.4e7), the first count that fits; a small scene keeps its 16.
    lo, hi = np.array([-10.0, -10.0, 0.0]), np.array([10.0, 10.0, 0.0])
    big = ProbeGrid.fit(lo, hi, 16, 8, triangles=1_000_000, max_triangle_draws=5e7)
    assert big.dims == (2, 2, 1)
    assert ProbeGrid.fit(lo, hi, 16, 8, triangles=3, max_triangle_draws=5e7).dims == (16, 16, 1)
    mid = ProbeGrid.fit(np.zeros(3), np.full(3, 2.0), 16, 8, triangles=10_000, max_triangle_draws=5e7)
    assert mid.dims == (9, 9, 9) and 6 * mid.count * 10_000 <= 5e7 < 6 * 10**3 * 10_000


def _probes(grid, needed):
    """The (ix, iy, iz) of the needed probes, sorted."""
    return sorted(tuple(int(v) for v in q[::-1]) for q in np.argwhere(needed.reshape(grid.dims[::-1])))


def test_read_by_marks_the_corners_of_every_cell_a_lookup_can_fall_in():
    # Probes at integer points 0..4 x 0..3 x 0..2 (spacing 1). A point at (1.5, 1.5, 0.5) lies in cell
    # (1, 1, 0): its 8 corners are read; a margin of 0.6 reaches cells 0..2 along each axis (clamped at
    # the grid's last cell, dims - 2); a point far outside falls in the lookup's clamped edge cell.
    grid = ProbeGrid(np.zeros(3), 1.0, (5, 4, 3), 8)
    point = np.array([[1.5, 1.5, 0.5]])
    assert _probes(grid, grid.read_by(point, point, 0.0)) == \
        sorted((x, y, z) for x in (1, 2) for y in (1, 2) for z in (0, 1))
    wide = _probes(grid, grid.read_by(point, point, 0.6))
    assert wide == sorted((x, y, z) for x in range(4) for y in range(4) for z in range(3))
    far = np.array([[-5.0, -5.0, -5.0]])
    assert _probes(grid, grid.read_by(far, far, 0.0)) == \
        sorted((x, y, z) for x in (0, 1) for y in (0, 1) for z in (0, 1))
    # Several boxes at once: the union of each one's probes; none at all: no probe.
    both = grid.read_by(np.r_[point, far], np.r_[point, far], 0.0)
    union = grid.read_by(point, point, 0.0) | grid.read_by(far, far, 0.0)
    assert (both == union).all() and both.sum() == 14  # the two cells share probes (1, 1, 0) and (1, 1, 1)
    assert not grid.read_by(np.zeros((0, 3)), np.zeros((0, 3)), 0.0).any()
    # A flat grid (one probe along z): its single layer is read wherever the point lies along z.
    flat = ProbeGrid(np.zeros(3), 1.0, (3, 3, 1), 8)
    assert _probes(flat, flat.read_by(np.array([[0.2, 0.2, 7.0]]), np.array([[0.2, 0.2, 7.0]]), 0.0)) == \
        [(0, 0, 0), (0, 1, 0), (1, 0, 0), (1, 1, 0)]


# Relocation (probe_grid.relocation_step). The capture is ray cast here in float64 against axis-aligned
# rectangles, as the rasterizer would fill the texels: the nearest rectangle along each texel's centre
# direction. Spacing 1 m, so clearances and bounds read in spacings.
N_RELOCATE = 8
CLEAR = RELOCATE_CLEARANCE_RATIO
BOUND = RELOCATE_MAX_OFFSET_RATIO
WIDE = (np.full(3, -10.0), np.full(3, 10.0))  # bounds far from every probe


def rect(axis, at, lo, hi, facing):
    """The rectangle {x[axis] = at, lo <= the other two coordinates <= hi} whose front faces `facing`
    (+1: the +axis side)."""
    return axis, at, np.asarray(lo, np.float64), np.asarray(hi, np.float64), facing


def solid_box(lo, hi):
    """The six faces of a closed box, fronts outwards."""
    lo, hi = np.asarray(lo, np.float64), np.asarray(hi, np.float64)
    faces = []
    for axis in range(3):
        others = [a for a in range(3) if a != axis]
        faces += [rect(axis, lo[axis], lo[others], hi[others], -1), rect(axis, hi[axis], lo[others], hi[others], +1)]
    return faces


def cast(pos, rects, n=N_RELOCATE):
    """The capture of a probe at `pos`: (seen, normal towards the probe, side, hit) per texel."""
    d = texel_directions(n)
    best = np.full(d.shape[:3], np.inf)
    seen, normal = np.zeros(d.shape), np.zeros(d.shape)
    side = np.zeros(d.shape[:3])
    for axis, at, lo, hi, facing in rects:
        others = [a for a in range(3) if a != axis]
        with np.errstate(divide="ignore", invalid="ignore"):
            t = (at - pos[axis]) / d[..., axis]
        x = pos + t[..., None] * d
        inside = np.all((x[..., others] >= lo) & (x[..., others] <= hi), axis=-1)
        take = (t > 1e-9) & inside & (t < best)
        best[take] = t[take]
        seen[take] = x[take]
        towards = np.sign(pos[axis] - at)
        normal[take] = np.eye(3)[axis] * towards
        side[take] = 1.0 if towards == facing else -1.0
    return seen, normal, side, np.isfinite(best)


def relocate(grid_pos, rects, offset=(0.0, 0.0, 0.0), bounds=WIDE):
    grid_pos, offset = np.asarray(grid_pos, np.float64), np.asarray(offset, np.float64)
    return relocation_step(grid_pos, offset, *cast(grid_pos + offset, rects), 1.0, *bounds)


FLOOR = rect(2, 0.0, (-5, -5), (5, 5), +1)


def test_a_probe_1_cm_above_a_floor_moves_to_the_clearance():
    # The floor z = 0 is 0.01 below the probe: the step is along its normal to CLEAR above it, so the
    # offset is exactly (0, 0, CLEAR - 0.01); float64 arithmetic on values of order 1, so 1e-12.
    offset = relocate((0.3, 0.2, 0.01), [FLOOR])
    np.testing.assert_allclose(offset, [0.0, 0.0, CLEAR - 0.01], rtol=0, atol=1e-12)


def test_a_second_step_leaves_a_relocated_probe_in_place():
    # From CLEAR above the floor the probe is no nearer than the clearance: no move (a step of float
    # rounding would be below RELOCATE_MIN_STEP_RATIO and is none): exactly the same offset back.
    first = relocate((0.3, 0.2, 0.01), [FLOOR])
    assert np.array_equal(relocate((0.3, 0.2, 0.01), [FLOOR], first), first)


def test_a_probe_in_a_corner_moves_off_both_surfaces_in_one_step():
    # Floor 0.02 below, wall x = 0 0.05 to the -x side: both near half-spaces are projected onto in
    # turn, and they are orthogonal, so the offset is exactly (CLEAR - 0.05, 0, CLEAR - 0.02).
    wall = rect(0, 0.0, (-5, -5), (5, 5), +1)
    offset = relocate((0.05, 0.0, 0.02), [FLOOR, wall])
    np.testing.assert_allclose(offset, [CLEAR - 0.05, 0.0, CLEAR - 0.02], rtol=0, atol=1e-12)


def test_no_probe_moves_without_geometry_near():
    # An empty world, and a floor 0.5 spacings away (beyond the clearance): the offset stays exactly 0.
    assert np.array_equal(relocate((0.0, 0.0, 0.0), []), np.zeros(3))
    assert np.array_equal(relocate((0.0, 0.0, 0.5), [FLOOR]), np.zeros(3))


def test_flipped_normals_move_an_open_probe_the_same_way():
    # Surfaces are two-sided: a probe that sees the sky somewhere is never "inside", so a floor seen
    # from its back moves it exactly as one seen from its front.
    back_floor = rect(2, 0.0, (-5, -5), (5, 5), -1)
    assert np.array_equal(relocate((0.3, 0.2, 0.01), [back_floor]), relocate((0.3, 0.2, 0.01), [FLOOR]))


def test_a_probe_inside_a_closed_box_moves_out_through_the_nearest_face():
    # The probe at z = 0.03 inside the box [-0.2, 0.2]^2 x [-0.2, 0.05] sees only back faces; the top
    # face is the nearest (0.02 away), so it leaves upwards to CLEAR above it: offset (0, 0, 0.02 + CLEAR).
    offset = relocate((0.0, 0.0, 0.03), solid_box((-0.2, -0.2, -0.2), (0.2, 0.2, 0.05)))
    np.testing.assert_allclose(offset, [0.0, 0.0, 0.02 + CLEAR], rtol=0, atol=1e-12)


def test_a_probe_deep_inside_a_solid_stays():
    # Half a spacing from every face of the box: leaving needs 0.5 + CLEAR > BOUND on some axis, and a
    # part-way move leaves it inside, so it stays (exactly 0).
    assert np.array_equal(relocate((0.0, 0.0, 0.0), solid_box((-0.5, -0.5, -0.5), (0.5, 0.5, 0.5))), np.zeros(3))


def test_a_probe_in_a_floor_slab_leaves_into_the_bounds():
    # A slab z in [-0.4, 0] spanning the scene, bounds from its bottom up: the probe at z = -0.3 is
    # nearer the bottom face (0.1) than the top (0.3), but leaving downwards ends below the bounds. Up:
    # 0.3 + CLEAR is clamped to BOUND, BOUND - 0.3 past the top (>= RELOCATE_MIN_EXIT_RATIO): offset
    # (0, 0, BOUND).
    slab = solid_box((-5, -5, -0.4), (5, 5, 0.0))
    bounds = (np.array([-5.0, -5.0, -0.4]), np.array([5.0, 5.0, 3.0]))
    np.testing.assert_allclose(relocate((0.0, 0.0, -0.3), slab, bounds=bounds), [0.0, 0.0, BOUND], atol=1e-12)
    # From z = -0.38 the clamped exit ends 0.07 past the top (< 0.1): it stays.
    assert np.array_equal(relocate((0.0, 0.0, -0.38), slab, bounds=bounds), np.zeros(3))


def test_offsets_never_exceed_the_bound():
    # Random closed boxes and floors around random probes, stepped three times: every offset component
    # within BOUND (the clamp is exact in float64).
    rng = np.random.default_rng(7)
    for _ in range(60):
        rects = [FLOOR] if rng.random() < 0.5 else []
        for _ in range(rng.integers(1, 4)):
            c, h = rng.uniform(-0.6, 0.6, 3), rng.uniform(0.05, 0.5, 3)
            rects += solid_box(c - h, c + h)
        grid_pos, offset = rng.uniform(-0.5, 0.5, 3), np.zeros(3)
        for _ in range(3):
            offset = relocate(grid_pos, rects, offset)
            assert np.abs(offset).max() <= BOUND
