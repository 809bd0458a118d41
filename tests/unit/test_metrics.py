"""addon.engine.metrics against answers worked out by hand (arithmetic in the comments)."""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest

from addon.engine import metrics
from addon.engine.errors import ConfigError


def rgb(values):
    """(h, w) list -> (h, w, 3) float array with the same value in R, G and B."""
    v = np.asarray(values, dtype=np.float64)
    return np.repeat(v[:, :, None], 3, axis=2)


def test_rel_rmse_by_hand():
    # diffs 0 and 1 -> mean sq 0.5 -> sqrt 0.70711; mean(b) = 1
    assert metrics.rel_rmse(rgb([[1, 2]]), rgb([[1, 1]])) == pytest.approx(math.sqrt(0.5))
    # mean(b) = 2: diffs 1, 1 -> rmse 1 -> 0.5
    assert metrics.rel_rmse(rgb([[3, 1]]), rgb([[2, 2]])) == pytest.approx(0.5)


def test_rel_rmse_uses_rgb_only_and_accepts_2d():
    a = rgb([[1, 2]])
    b = np.concatenate([rgb([[1, 1]]), np.full((1, 2, 1), 123.0)], axis=2)  # alpha must be ignored
    assert metrics.rel_rmse(a, b) == pytest.approx(math.sqrt(0.5))
    assert metrics.rel_rmse(np.array([[1.0, 2.0]]), np.array([[1.0, 1.0]])) == pytest.approx(math.sqrt(0.5))


def test_mask_excludes_pixels():
    a, b = rgb([[3, 100]]), rgb([[2, 50]])
    mask = np.array([[True, False]])
    # only pixel 0: |3-2| / 2 = 0.5 ; bias 3/2
    assert metrics.rel_rmse(a, b, mask) == pytest.approx(0.5)
    assert metrics.bias(a, b, mask) == pytest.approx(1.5)
    # unmasked: diffs 1, 50 -> sqrt((1 + 2500)/2) = 35.362; mean(b) = 26 -> 1.36008
    assert metrics.rel_rmse(a, b) == pytest.approx(math.sqrt(2501 / 2) / 26)


def test_rel_rmse_8_averages_noise_away():
    # 8 x 16: left block a = 2 (b = 1); right block a alternates 0/2 (mean 1, b = 1).
    a = np.full((8, 16), 2.0)
    a[:, 8:] = np.indices((8, 8)).sum(axis=0) % 2 * 2.0
    b = np.ones((8, 16))
    # per pixel every |a-b| is 1 -> rel_rmse 1
    assert metrics.rel_rmse(a, b) == pytest.approx(1.0)
    # blocks: (2 vs 1) and (1 vs 1), 64 pixels each -> sqrt((1 + 0) / 2) / 1 = 0.70711
    assert metrics.rel_rmse_8(a, b) == pytest.approx(math.sqrt(0.5))


def test_rel_rmse_8_mask_inside_blocks_and_weighting():
    # left block fully masked, a = b = 1; right block only pixel (0, 8) masked with a = 3, b = 1;
    # the unmasked rest of the right block has a = 1000 and must not leak into its average.
    a = np.ones((8, 16))
    a[:, 8:] = 1000.0
    a[0, 8] = 3.0
    b = np.ones((8, 16))
    mask = np.zeros((8, 16), dtype=bool)
    mask[:, :8] = True
    mask[0, 8] = True
    # blocks: left (1 vs 1, n = 64), right (3 vs 1, n = 1); weighted by n:
    # sqrt((64 * 0 + 1 * 4) / 65) / 1 = 0.24807 (equal block weights would give sqrt(2) instead)
    assert metrics.rel_rmse_8(a, b, mask) == pytest.approx(math.sqrt(4 / 65))


def test_rel_rmse_8_partial_blocks():
    # 1 x 9: blocks of 8 and 1 pixels. a = 1 x 8 then 5, b = 1 -> block means (1, 5) vs (1, 1),
    # weights 8, 1 -> sqrt(1 * 16 / 9) / 1 = 4/3
    a = np.array([[1.0] * 8 + [5.0]])
    b = np.ones((1, 9))
    assert metrics.rel_rmse_8(a, b) == pytest.approx(4 / 3)


def test_rel_rmse_8_with_block_1_is_rel_rmse():
    rng = np.random.default_rng(1)
    a, b = rng.random((13, 11, 3)), rng.random((13, 11, 3)) + 0.1
    mask = rng.random((13, 11)) > 0.3
    assert metrics.rel_rmse_8(a, b, mask, block=1) == pytest.approx(metrics.rel_rmse(a, b, mask))


def test_bias_by_hand():
    assert metrics.bias(rgb([[2, 4]]), rgb([[1, 1]])) == pytest.approx(3.0)  # mean 3 / mean 1


def test_compare_dict():
    a, b = rgb([[3, 100]]), rgb([[2, 50]])
    got = metrics.compare(a, b, np.array([[True, False]]))
    assert got == {"rel_rmse": pytest.approx(0.5), "rel_rmse_8": pytest.approx(0.5),
                   "bias": pytest.approx(1.5), "pixels": 1, "note": None}


def test_zero_reference_gives_none_not_nan():
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # a 0/0 in numpy would warn
        got = metrics.compare(rgb([[1, 2]]), rgb([[0, 0]]))
        empty = metrics.compare(rgb([[1, 2]]), rgb([[1, 1]]), np.zeros((1, 2), dtype=bool))
    assert got["rel_rmse"] is None and got["rel_rmse_8"] is None and got["bias"] is None
    assert got["pixels"] == 2 and "reference mean is 0" in got["note"]
    assert empty["rel_rmse"] is None and empty["pixels"] == 0 and "no pixel" in empty["note"]


def test_size_mismatch_is_config_error():
    with pytest.raises(ConfigError, match="differ in size"):
        metrics.compare(np.zeros((4, 4, 3)), np.zeros((4, 5, 3)))
    with pytest.raises(ConfigError, match="mask shape"):
        metrics.compare(np.zeros((4, 4, 3)), np.zeros((4, 4, 3)), np.ones((3, 4), dtype=bool))


CURVE = [(1.0, 0.4), (4.0, 0.2), (16.0, 0.1)]  # error halves per 4x time: error ~ 1/sqrt(t)


def test_speedup_interpolates_log_log():
    # 0.2 * sqrt(2) is half-way (in log) between 0.4 and 0.2 -> log t half-way between 1 and 4 -> t = 2
    got = metrics.cycles_equivalent_speedup(0.2 * math.sqrt(2), 0.5, CURVE)
    assert got["bound"] == "=" and got["cycles_time_s"] == pytest.approx(2.0)
    assert got["speedup"] == pytest.approx(4.0) and got["extrapolated_speedup"] is None
    # exactly on a point
    got = metrics.cycles_equivalent_speedup(0.1, 4.0, CURVE)
    assert got["bound"] == "=" and got["speedup"] == pytest.approx(4.0)  # 16 / 4


def test_speedup_beyond_curve_ends_returns_bounds():
    # worse than Cycles' fastest point: Cycles needs at most 1 s -> speed-up at most 1 / 0.5 = 2
    got = metrics.cycles_equivalent_speedup(0.5, 0.5, CURVE)
    assert got["bound"] == "<" and got["speedup"] == pytest.approx(2.0)
    # better than Cycles' slowest point: at least 16 / 2 = 8; extrapolated 16 * (0.1/0.05)^2 / 2 = 32
    got = metrics.cycles_equivalent_speedup(0.05, 2.0, CURVE)
    assert got["bound"] == ">" and got["speedup"] == pytest.approx(8.0)
    assert got["extrapolated_speedup"] == pytest.approx(32.0)


def test_speedup_takes_dicts_unsorted_and_first_crossing():
    curve = [{"time_s": 4.0, "rel_rmse_8": 0.2, "spp": 64}, {"time_s": 1.0, "rel_rmse_8": 0.4, "spp": 16},
             {"time_s": 16.0, "rel_rmse_8": 0.25, "spp": 256}]  # noisy: last point worse again
    got = metrics.cycles_equivalent_speedup(0.2, 1.0, curve)
    assert got["bound"] == "=" and got["cycles_time_s"] == pytest.approx(4.0)
    with pytest.raises(ConfigError):
        metrics.cycles_equivalent_speedup(0.2, 0.0, CURVE)
    with pytest.raises(ConfigError):
        metrics.cycles_equivalent_speedup(0.2, 1.0, [])


def test_hdr_flip():
    pytest.importorskip("flip_evaluator")
    rng = np.random.default_rng(0)
    b = rng.random((32, 32, 3))
    assert metrics.hdr_flip(b, b) == pytest.approx(0.0, abs=1e-7)
    mask = np.zeros((32, 32), dtype=bool)
    mask[8:24, 8:24] = True
    a = b.copy()
    a[~mask] = 50.0  # differences outside the mask must not count
    assert metrics.hdr_flip(a, b, mask) == pytest.approx(0.0, abs=1e-7)
    assert metrics.hdr_flip(b * 2, b) > 0.05


def test_error_against_noisy_checks_without_noise_is_rel_rmse_8():
    # Two equal checks: their spread is 0, so nothing is subtracted and the estimate is rel_rmse_8 itself.
    rng = np.random.default_rng(0)
    a, c = rng.uniform(0.5, 1.5, (16, 24, 3)), rng.uniform(0.5, 1.5, (16, 24, 3))
    assert metrics.rel_rmse_8_against_noisy(a, [c, c]) == pytest.approx(metrics.rel_rmse_8(a, c), rel=1e-12)
    assert metrics.rel_noise_8([c, c]) == 0.0
    with pytest.raises(ConfigError):
        metrics.rel_rmse_8_against_noisy(a, [c])


def test_error_against_noisy_checks_removes_their_noise():
    # Truth T: a smooth field; A = T (1 + 0.1 s) with s = +-1 per 8 x 8 block, so A's rel_rmse_8 against
    # T is exactly e0 = 0.1 sqrt(mean T_b^2) / mean T = 0.105. The checks: T plus independent Gaussian
    # noise of sd 1 per pixel and channel, so their mean's rel_noise_8 (0.11) is as large as A's error,
    # as the path-traced check's is by design (choice.CHECK_NOISE): against their mean A reads ~1.46 e0,
    # with their noise subtracted e0. E[D^2 - N^2] = e0^2 exactly, so over 40 seeds the mean of the
    # estimates' squares must lie within 4 of its standard errors (measured from the 40) of e0^2. Over
    # these 384 blocks x 3 channels a single estimate's spread is 4.4 % of e0: each within 15 % (3.4 sd).
    h, w = 128, 192
    y, x = np.mgrid[0:h, 0:w]
    t = (1.0 + 0.5 * np.sin(x / 17.0) * np.cos(y / 11.0))[:, :, None] * np.array([1.0, 0.8, 0.6])
    blocks = np.where(((x // 8) + (y // 8)) % 2 == 0, 1.0, -1.0)[:, :, None]
    a = t * (1.0 + 0.1 * blocks)
    e0 = metrics.rel_rmse_8(a, t)
    squares, naive = [], []
    for seed in range(40):
        rng = np.random.default_rng(seed)
        checks = [t + rng.normal(0.0, 1.0, t.shape) for _ in range(2)]
        e = metrics.rel_rmse_8_against_noisy(a, checks)
        assert e == pytest.approx(e0, rel=0.15)
        squares.append(e * e)
        naive.append(metrics.rel_rmse_8(a, (checks[0] + checks[1]) / 2))
    stderr = np.std(squares, ddof=1) / math.sqrt(len(squares))
    assert abs(np.mean(squares) - e0 * e0) < 4 * stderr
    assert np.mean(naive) > 1.3 * e0  # what the subtraction takes away


def test_noise_of_noisy_checks():
    # Pixels of sd 1 around a mean of 4: a full 8 x 8 block's mean has variance 1/64, the mean of two
    # renders 1/128; rel_noise_8 = sqrt(1/128) / 4 = 0.0221. Over 48 x 64 px (48 blocks, 3 channels),
    # its estimate from two renders has a relative sd of about 1 / sqrt(2 x 144) = 6 %: 20 % is 3 sd.
    rng = np.random.default_rng(3)
    checks = [4.0 + rng.normal(0.0, 1.0, (48, 64, 3)) for _ in range(2)]
    assert metrics.rel_noise_8(checks) == pytest.approx(math.sqrt(1 / 128) / 4, rel=0.2)
    # A mask: blocks count by their masked pixels, as rel_rmse_8 weighs them; nothing masked is None.
    assert metrics.rel_noise_8(checks, np.zeros((48, 64), bool)) is None
