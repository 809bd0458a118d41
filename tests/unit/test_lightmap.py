"""Bake helpers: seam dilation (exact), safe output paths, shard selection."""

from pathlib import Path

import numpy as np
import pytest

from addon.engine.errors import ConfigError
from addon.engine.lightmap import dilate, output_path, parse_shard, safe_name, shard, uv_problems


def test_dilation_fills_rings_with_neighbour_means_exactly():
    img = np.zeros((5, 5, 1))
    cov = np.zeros((5, 5), bool)
    img[2, 2], cov[2, 2] = 8.0, True
    img[2, 3], cov[2, 3] = 4.0, True
    out, filled = dilate(img, cov, 1)
    # Ring 1: each empty texel = mean of its covered 8-neighbours (covered texels unchanged).
    assert out[2, 2, 0] == 8.0 and out[2, 3, 0] == 4.0
    assert out[1, 1, 0] == 8.0 and out[1, 2, 0] == 6.0 and out[1, 4, 0] == 4.0 and out[2, 1, 0] == 8.0
    assert filled.sum() == 2 + 10 and not filled[0].any()
    out2, filled2 = dilate(img, cov, 2)
    assert filled2.all()
    # Ring 2: corner (0, 0) sees only (1, 1) of ring 1.
    assert out2[0, 0, 0] == 8.0
    np.testing.assert_array_equal(out2[1:4, 1:5], out[1:4, 1:5])  # ring 1 unchanged by ring 2


def test_dilation_without_coverage_is_a_no_op():
    img = np.ones((3, 3, 3))
    out, filled = dilate(img, np.zeros((3, 3), bool), 4)
    assert not filled.any() and np.array_equal(out, img)


@pytest.mark.parametrize("name", ["../x", "../../etc/passwd", "a/b\\c", "..", ".hidden", "/abs", "C:\\x", "", "é ñ"])
def test_output_paths_never_leave_the_directory(tmp_path, name):
    p = output_path(tmp_path, name, "indirect")
    assert p.parent == tmp_path.resolve() and p.name.endswith("_indirect.exr")
    assert "/" not in safe_name(name) and "\\" not in safe_name(name) and ".." not in safe_name(name)
    assert not safe_name(name).startswith(".")


def test_names_that_sanitise_alike_get_distinct_files(tmp_path):
    taken: set[str] = set()
    a = output_path(tmp_path, "a/b", "direct", taken)
    b = output_path(tmp_path, "a:b", "direct", taken)
    assert a != b and Path(b).name == "a_b_direct_2.exr"


def test_shards_are_disjoint_and_cover_everything():
    names = [f"o{i}" for i in range(10)]
    parts = [shard(names, i, 3) for i in range(3)]
    assert sorted(sum(parts, [])) == sorted(names)
    assert parts[1] == sorted(names)[1::3]
    assert parse_shard("2/5") == (2, 5) and parse_shard(None) == (0, 1)
    for bad in ("5/5", "1", "-1/2", "a/b", "0/0"):
        with pytest.raises(ConfigError):
            parse_shard(bad)


def test_uv_problems():
    pos = np.array([[[0, 0, 0], [1, 0, 0], [0, 1, 0]]] * 2, float)
    uv = np.array([[[0, 0], [1, 0], [0, 1]], [[0.5, 0.5]] * 3], float)
    notes = uv_problems(uv, pos)
    assert len(notes) == 1 and "1 of 2 triangles have zero UV area" in notes[0]
    assert "outside 0..1" in uv_problems(uv + 1.5, pos)[-1]


def test_block_mean_averages_only_covered_sub_texels():
    # 4 x 4 sub-texels, factor 2: texel (0, 0) all covered (values 1, 2, 3, 4: mean 2.5), texel (0, 1)
    # one covered (7), texel (1, 0) none (0, uncovered), texel (1, 1) two covered (2 and 6: 4). An
    # uncovered sub-texel's value never counts, whatever it holds.
    from addon.engine.lightmap import block_mean

    v = np.zeros((4, 4, 4))
    v[0:2, 0:2, 0] = [[1, 2], [3, 4]]
    v[0:2, 0:2, 3] = 1
    v[0, 2, 0], v[0, 2, 3], v[1, 3, 0] = 7, 1, 100  # (1, 3) holds 100 but is not covered
    v[2:4, 0:2, 0] = 50  # none covered
    v[2, 2, 0], v[3, 3, 0] = 2, 6
    v[2, 2, 3] = v[3, 3, 3] = 1
    out = block_mean(v, 2)
    assert out[..., 0].tolist() == [[2.5, 7.0], [0.0, 4.0]]
    assert out[..., 3].tolist() == [[1, 1], [0, 1]]
    assert block_mean(v, 1) is v
    with pytest.raises(ValueError):
        block_mean(v[:3], 2)


def test_block_mean_prefers_sub_texels_whose_centres_are_covered():
    # Alpha 1: the surface covers the sub-texel's centre; CONSERVATIVE_COVERAGE: it only touches its
    # square (the value is the surface's nearest point, at its very edge). Texel (0, 0): centred 2 and 4,
    # touched 100 -> 3, alpha 1. Texel (0, 1): only touched ones, 5 and 7 -> 6, alpha CONSERVATIVE.
    from addon.engine.lightmap import block_mean
    from addon.engine.passes.bake_gbuffer import CONSERVATIVE_COVERAGE as C

    v = np.zeros((2, 4, 4))
    v[0, 0:2, 0], v[0, 0:2, 3] = [2, 4], 1
    v[1, 0, 0], v[1, 0, 3] = 100, C
    v[0, 2, 0], v[1, 3, 0] = 5, 7
    v[0, 2, 3] = v[1, 3, 3] = C
    out = block_mean(v, 2)
    assert out[..., 0].tolist() == [[3.0, 6.0]]
    assert out[..., 3].tolist() == [[1.0, C]]


def test_check_supersample_bounds_the_factor_and_the_texels():
    from addon.engine.lightmap import SUPERSAMPLE_MAX, check_supersample

    assert check_supersample(1, 8192) == 1 and check_supersample(SUPERSAMPLE_MAX, 1024) == SUPERSAMPLE_MAX
    for factor, size in ((0, 64), (SUPERSAMPLE_MAX + 1, 64), (2, 8192), (4, 4096)):
        with pytest.raises(ConfigError):
            check_supersample(factor, size)
