"""The measurement helpers of docs/GATHER.md: tools/brightest_pixels.py and tools/near_wall_error.py."""

import importlib.util
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]


def _tool(name):
    spec = importlib.util.spec_from_file_location(name, ROOT / "tools" / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_brightest_share_is_the_mean_of_the_top_pixels_over_the_references():
    # 100 covered pixels of values 1..100 (RGB equal); one pixel without geometry at 1000 is ignored. The
    # brightest 1 % is the one pixel at 100; ours is the reference x 2 plus a spike of 500 in one pixel,
    # so its brightest 1 % is that spike: ratio 500 / 100 exactly; at 10 %, (500 + 2 x (100 + ... + 92)) / 10
    # over (100 + ... + 91) / 10.
    bp = _tool("brightest_pixels")
    values = np.r_[np.arange(1.0, 101.0), 1000.0]
    ref = np.zeros((1, 101, 4))
    ref[0, :, :3] = values[:, None]
    ref[0, :100, 3] = 1.0
    ours = ref.copy()
    ours[0, :, :3] *= 2.0
    ours[0, 0, :3] = 500.0
    assert bp.compare(ours, ref)["ratio"] == 5.0
    top = np.sort(2.0 * np.arange(2.0, 101.0))[::-1][:9]
    assert np.isclose(bp.compare(ours, ref, 0.1)["ratio"], (500.0 + top.sum()) / np.arange(91.0, 101.0).sum())


def test_near_wall_mask_is_the_distance_to_a_second_side_of_the_bounds():
    # In the unit cube, a floor point (z = 0) 0.03 from the wall x = 0 is near at 0.05 and not at 0.02; the
    # floor's centre is near no second wall; a pixel without geometry never counts.
    nw = _tool("near_wall_error")
    position = np.array([[[0.03, 0.5, 0.0, 1.0], [0.5, 0.5, 0.0, 1.0], [0.01, 0.01, 0.0, 0.0]]])
    lo, hi = np.zeros(3), np.ones(3)
    assert nw.near_wall_mask(position, lo, hi, 0.05).tolist() == [[True, False, False]]
    assert nw.near_wall_mask(position, lo, hi, 0.02).tolist() == [[False, False, False]]
