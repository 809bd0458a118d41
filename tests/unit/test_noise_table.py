"""tools/noise_table.py without a GPU: its --set parsing and the settings it builds."""

import importlib.util
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
_spec = importlib.util.spec_from_file_location("noise_table", ROOT / "tools" / "noise_table.py")
noise_table = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(noise_table)


def test_sets_parse_by_group():
    assert noise_table.parse_sets(["vct.diffuse_cones=24", "gi.denoise=false", "vct.offset_cells=1.0"]) == {
        "vct": {"diffuse_cones": "24", "offset_cells": "1.0"}, "gi": {"denoise": "false"}}
    with pytest.raises(SystemExit):
        noise_table.parse_sets(["diffuse_cones=24"])


def test_settings_take_the_field_types_and_the_run_overrides():
    sets = noise_table.parse_sets(["vct.diffuse_cones=24", "gi.denoise=off", "gi.seed=5"])
    found = noise_table.build_settings("vct", 128, sets, seed=1)
    assert found["vct"].diffuse_cones == 24  # int from "24"
    assert found["gi"].denoise is False  # "off" is a bool
    assert (found["gi"].method, found["gi"].resolution, found["gi"].seed) == ("vct", 128, 1)  # the run's seed wins
    assert found["rsm"].vpl_samples == 256  # groups not set keep their defaults


def test_pair_noise_is_the_root_mean_square_over_the_seed_pairs():
    # Pairs (0, 1) and (2, 3): image 1 is 10 % above image 0 and image 3 30 % above image 2 on every
    # covered pixel, so their rel_rmse are 0.1 and 0.3 (relative to the first image's mean) and the
    # root mean square sqrt((0.01 + 0.09) / 2) = 0.2236. The uncovered pixel (mask False) is left out.
    import numpy as np

    base = np.ones((2, 2, 3), np.float32)
    mask = np.array([[True, True], [True, False]])
    images = [base, base * 1.1, base * 2, base * 2.6]
    images[1][1, 1] = 50.0  # uncovered: ignored
    noise, pairs = noise_table.pair_noise(images, mask)
    assert pairs == pytest.approx([0.1, 0.3], rel=1e-5)
    assert noise == pytest.approx(np.sqrt(0.05), rel=1e-5)
