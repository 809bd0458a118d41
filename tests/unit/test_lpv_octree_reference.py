"""The octree LPV's numpy reference (addon/engine/lpv_octree_reference.py) against exact answers.

Fields are (z, y, x, 4) L1 SH of radiant intensity (W/sr); a cell's flux is 2 sqrt(pi) c0
(lpv_reference.flux_w), linear in the coefficients, so sums and conservation are exact up to float64
rounding.
"""

import numpy as np
import pytest

from addon.engine import lpv_octree_reference as octree
from addon.engine import lpv_reference as ref
from addon.engine import sh
from addon.engine.passes import lpv_octree


def point_source(shape_zyx, src_xyz, watts=1.0):
    field = np.zeros(tuple(shape_zyx) + (4,))
    field[src_xyz[2], src_xyz[1], src_xyz[0], 0] = watts / ref.FLUX_PER_C0  # isotropic: c0 alone
    return field


def test_level_dims_halve_rounding_up():
    # ceil(d / 2) per level: a coarse cell j holds cells 2j, 2j + 1 of the level below.
    assert octree.level_dims((32, 20, 7), 5) == [(32, 20, 7), (16, 10, 4), (8, 5, 2), (4, 3, 1), (2, 2, 1)]


def test_downsample_sums_children_and_keeps_flux():
    # Intensity is additive: a coarse cell emits what its 8 children emit, children beyond odd dims
    # absent. Exact in float64 (1e-12 relative: summation order).
    rng = np.random.default_rng(3)
    field = rng.normal(size=(5, 6, 7, 4))
    coarse = octree.downsample(field)
    assert coarse.shape == (3, 3, 4, 4)
    np.testing.assert_allclose(coarse[1, 2, 3], field[2:4, 4:6, 6:8].sum(axis=(0, 1, 2)), rtol=1e-12)
    np.testing.assert_allclose(coarse[2, 0, 0], field[4:5, 0:2, 0:2].sum(axis=(0, 1, 2)), rtol=1e-12)
    levels = octree.chain(field, 4)
    for level in levels:
        assert ref.flux_w(level) == pytest.approx(ref.flux_w(field), rel=1e-12)


def test_downsample_voxels_of_a_wall_across_a_coarse_cell():
    # A wall at x = 1 (fine cells) across a 2x2x2 block: the x-children at index 1 each project 1 cell^2
    # along x with offset -0.5 (the wall on their low face). The coarse cell: area 4 / 4 = 1 coarse
    # cell^2; position = child centre (1 - 0.5 = +0.5 from the coarse centre) - 0.5 = 0 fine cells, so
    # offset 0 coarse cells: the wall lies at the coarse cell's centre. Exact.
    projected = np.zeros((2, 2, 2, 4))
    offset = np.zeros((2, 2, 2, 4))
    projected[:, :, 1, 0] = 1.0
    projected[:, :, 1, 3] = 1.0
    offset[:, :, 1, 0] = -0.5
    p, o = octree.downsample_voxels(projected, offset)
    np.testing.assert_allclose(p[0, 0, 0], [1.0, 0.0, 0.0, 1.0], atol=1e-15)
    np.testing.assert_allclose(o[0, 0, 0], [0.0, 0.0, 0.0, 0.0], atol=1e-15)
    offset[:, :, 1, 0] = 0.25  # the wall 0.75 fine cells right of the coarse centre: 0.375 coarse cells
    _, o = octree.downsample_voxels(projected, offset)
    assert o[0, 0, 0, 0] == pytest.approx(0.375, abs=1e-15)


def test_upsample_keeps_the_reading_and_the_light():
    # A uniform coarse accumulation reads the same from both levels: 1/4 of it per fine cell
    # ((h / 2h)^2, the lookup divides by h^2). Its path-length integral sum(acc) x cell size is kept:
    # 8 fine cells of acc / 4 at h = one coarse cell of acc at 2h. Exact (weights are dyadic).
    coarse = np.full((3, 4, 5, 4), 2.0)
    np.testing.assert_allclose(octree.upsample(coarse, (6, 8, 10)), 0.5, rtol=0, atol=1e-15)
    rng = np.random.default_rng(5)
    coarse = rng.uniform(0, 1, (4, 4, 4, 4))
    fine = octree.upsample(coarse, (8, 8, 8))
    assert fine.sum() * 1.0 == pytest.approx(coarse.sum() * 2.0, rel=1e-12)


@pytest.mark.parametrize("k", [2, 4])
def test_index_rule_is_the_finest_level_holding_light(k):
    # One isotropic source in a 16^3 grid, 4 levels, k steps each. The improved transport moves light
    # one axis step per step, and every transfer of an isotropic source's light has c0 > 0 ahead of it
    # (M00 = 1/6 dominates), so after k steps level i holds light exactly at its cells within Manhattan
    # distance 1..k of the source's cell src >> i (the source's own cell is not accumulated; what comes
    # back to it is L1 back-bleeding, left out here). With eps -> 0 (the paper's "non-zero" rule) the
    # index is the finest such level, the coarsest where none holds light.
    n, levels, src = 16, 4, np.array([5, 9, 6])
    accs = octree.propagate(octree.chain(point_source((n, n, n), src), levels), k)
    zero = np.zeros_like
    _, weights = octree.merge([[a, zero(a), zero(a)] for a in accs], epsilon=1e-9)
    index = octree.index_volume(weights)
    expected = np.full((n, n, n), levels - 1)
    z, y, x = np.indices((n, n, n))
    for i in reversed(range(levels - 1)):
        s = src >> i
        d = np.abs((x >> i) - s[0]) + np.abs((y >> i) - s[1]) + np.abs((z >> i) - s[2])
        expected = np.where((d >= 1) & (d <= k), i, expected)
    own = (x == src[0]) & (y == src[1]) & (z == src[2])
    assert np.array_equal(index[~own], expected[~own])
    assert set(np.unique(index)) >= {0, 1}  # the rule picks more than one level here


def test_merge_creates_no_light():
    # Each merged coefficient is a convex combination of the finer level's and the upsampled coarser
    # answer's, per cell: it lies between them (float64, 1e-12 slack for rounding). Random fields with
    # negative coefficients too, three levels, several eps.
    rng = np.random.default_rng(9)
    shapes = [(8, 6, 8), (4, 3, 4), (2, 2, 2)]
    accs = [[rng.normal(0.3, 1.0, s + (4,)) for _ in range(3)] for s in shapes]
    for eps in (1e-6, 0.25, 0.5):
        merged_1, _ = octree.merge(accs[1:], eps)
        merged_0, weights = octree.merge(accs, eps)
        for fine, m1, m0 in zip(accs[0], merged_1, merged_0, strict=True):
            up = octree.upsample(m1, shapes[0])
            assert np.all(m0 >= np.minimum(fine, up) - 1e-12) and np.all(m0 <= np.maximum(fine, up) + 1e-12)
        assert all(np.all((w >= 0) & (w <= 1)) for w in weights)
        assert 0 < np.mean(weights[0]) < 1  # both levels are used: the test measures the blend


def test_merge_weight_ramp():
    # w = clamp(rho / eps - 1, 0, 1): 0 up to rho = eps, linear to 1 at 2 eps; the finer level alone
    # where the coarser answer holds no light, nothing where neither does. Exact.
    fine = np.array([0.0, 0.25, 0.375, 0.5, 2.0, 1.0, 0.0, -1.0])
    coarse = np.array([1.0, 1.0, 1.0, 1.0, 1.0, 0.0, 0.0, 1.0])
    np.testing.assert_array_equal(octree.weight(fine, coarse, 0.25), [0, 0, 0.5, 1, 1, 1, 0, 0])


def test_energy_is_never_gained_on_any_level():
    # Per level, each step's flux is at most the previous snapshot's: sum_d M_d = identity and the
    # geometry volume's pass-through is in [0, 1]. A random geometry volume downsampled like the GPU's.
    rng = np.random.default_rng(2)
    n, levels = 12, 3
    field = np.zeros((n, n, n, 4))
    for _ in range(20):
        z, y, x = rng.integers(0, n, 3)
        d = rng.normal(size=3)
        field[z, y, x] += rng.uniform(0.1, 1.0) * sh.cosine_lobe_l1(d / np.linalg.norm(d)) / np.pi
    projected = rng.uniform(0, 1.2, (n, n, n, 4)) * (rng.random((n, n, n, 1)) < 0.3)
    offset = rng.uniform(-0.5, 0.5, (n, n, n, 4))
    matrices, _ = ref.gpu_improved_transfer()
    snapshots = octree.chain(field, levels)
    for level in range(levels):
        through = ref.pass_through(*ref.blocking(projected, offset))
        current = snapshots[level]
        flux = [ref.flux_w(current)]
        for _ in range(6):
            current = ref.step(current, matrices, through)
            flux.append(ref.flux_w(current))
        assert np.all(np.diff(flux) <= 1e-12 * flux[0]), (level, flux)
        assert flux[-1] < 0.9 * flux[0]  # walls and borders took light: the bound was tested
        projected, offset = octree.downsample_voxels(projected, offset)


def point_source_profile(k, epsilon, n=32, levels=5):
    """An isotropic 1 W source at x = 4 in an empty n^3 grid through the octree: irradiance on a
    surface facing it at cell centres along +x, octree / exact (I / r^2, I = 1 / (4 pi) W/sr)."""
    src = (4, n // 2, n // 2)
    accs = octree.propagate(octree.chain(point_source((n, n, n), src), levels), k)
    zero = np.zeros_like
    merged, _ = octree.merge([[a, zero(a), zero(a)] for a in accs], epsilon)
    lobe = sh.cosine_lobe_l1(np.array([1.0, 0.0, 0.0]))  # receiver normal -x
    return {r: max(merged[0][src[2], src[1], src[0] + r] @ lobe, 0.0) / (1.0 / (4 * np.pi) / r**2)
            for r in range(1, n - src[0])}


def test_point_source_irradiance_falls_as_inverse_square():
    # Measured (LPV / exact at 1, 2, 3, 4, 6, 8, 12, 16, 20, 24, 27 cells), k = 4, 5 levels:
    #   eps 0.5:  0.84 1.62 1.26 1.25 1.41 1.26 1.37 1.05 0.93 0.97 1.09
    #   eps 1e-6: 0.84 1.62 1.26 0.92 1.41 1.12 1.37 1.05 0.93 0.97 1.09
    #   k = 8, eps 0.5: 0.74 1.46 1.93 1.97 1.56 1.91 1.53 1.85 1.57 1.43 1.67
    # One grid over its whole span stays in [0.6, 1.9] (tests/gpu/test_lpv.py): the octree keeps that
    # band at k = 4, the L1 transport's on-axis excess and not the level switches setting its width;
    # the bound is [0.6, 2.0] for k = 8's 1.97. With k = 8 and the paper's non-zero rule the reading
    # drops to 0.11 x at 8 cells, where level 0's light is just arriving and wins the switch; eps = 0.5
    # skips it (1.91 there): the dip is the paper's "intensity jump where the chosen level changes",
    # and the test fails if it comes back.
    for k, eps in ((4, 0.5), (4, 1e-6), (8, 0.5)):
        profile = point_source_profile(k, eps)
        for r in range(2, 28):
            assert 0.6 <= profile[r] <= 2.0, (k, eps, r, profile[r])
    paper = point_source_profile(8, 1e-6)
    assert min(paper[r] for r in range(2, 28)) < 0.2


@pytest.mark.parametrize("k, levels", [(4, 5), (8, 5), (6, 3), (1, 2)])
def test_time_shares_count_every_flight_time_once(k, levels):
    # Level i's step s stands for the fine flight time t = s 2^i. At every t that each level has a step
    # for (t a multiple of 2^(levels-1)) the shares sum to exactly 1 (they telescope: g_i - g_{i-1},
    # the coarsest 1 - g_{L-2}); each lies in [0, 1]; no level but the coarsest counts a step beyond its
    # `steps`, and the last step each finer level runs has a share.
    for t in range(2 ** (levels - 1), 4 * k * 2 ** (levels - 1), 2 ** (levels - 1)):
        shares = [lpv_octree.time_share(i, t // 2**i, k, levels) for i in range(levels)]
        assert all(0.0 <= w <= 1.0 for w in shares), (t, shares)
        assert sum(shares) == pytest.approx(1.0, abs=1e-15), (t, shares)
    for i in range(levels - 1):
        last = lpv_octree.steps(i, k, levels, "time", coarsest_span=0)
        assert all(lpv_octree.time_share(i, s, k, levels) == 0.0 for s in range(last + 1, 4 * k))
        assert k == 1 or lpv_octree.time_share(i, last, k, levels) > 0.0
    assert lpv_octree.steps(levels - 1, k, levels, "time", coarsest_span=7) == max(k, 7)
    assert all(lpv_octree.steps(i, k, levels, "index", 7) == k for i in range(levels))


def test_time_merge_point_source_against_inverse_square():
    # The time merge (k = 8, 5 levels) with an isotropic 1 W source at x = 4 of a 32^3
    # grid, read along +x as point_source_profile does. Measured LPV / exact at 1, 2, 3, 4, 6, 8, 12,
    # 16, 20, 24, 27 cells: 0.76 1.53 1.67 1.44 1.08 1.38 1.26 1.52 1.38 1.22 1.34 (k = 4: 0.83 1.42
    # 0.95 0.85 1.11 0.92 1.10 0.80 0.71 0.67 0.72, the flight times the levels' short ramps miss).
    # Bound: one grid's band [0.6, 1.9] over 2..27 cells.
    n, levels, k, src = 32, 5, 8, (4, 16, 16)
    snapshots = octree.chain(point_source((n, n, n), src), levels)
    steps = [lpv_octree.steps(i, k, levels, "time", sum(s.shape[:3]) - 3) for i, s in enumerate(snapshots)]
    shares = [lambda s, i=i: lpv_octree.time_share(i, s, k, levels) for i in range(levels)]
    accs = octree.propagate(snapshots, steps, shares=shares)
    zero = np.zeros_like
    merged = octree.add_up([[a, zero(a), zero(a)] for a in accs])[0]
    lobe = sh.cosine_lobe_l1(np.array([1.0, 0.0, 0.0]))
    for r in range(2, 28):
        ratio = max(merged[src[2], src[1], src[0] + r] @ lobe, 0.0) / (1.0 / (4 * np.pi) / r**2)
        assert 0.6 <= ratio <= 1.9, (r, ratio)
