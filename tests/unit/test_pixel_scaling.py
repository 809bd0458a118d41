"""tools/pixel_scaling.py splits a method's update into a fixed part and a part that grows with the
pixels, from its times at two pixel counts, and states the growing part's share at the choice model's
reference pixel count."""

import importlib.util
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]


def _pixel_scaling():
    spec = importlib.util.spec_from_file_location("pixel_scaling", ROOT / "tools" / "pixel_scaling.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_per_pixel_share_from_two_timings():
    # t = 100 ms + 10 ms per 16384 pixels: 110 ms at 16384 pixels, 140 at 65536; at the reference
    # (16384 pixels) 10 of the 110 ms grow with the pixels. Equal times: nothing grows; 4x the time at 4x
    # the pixels: all of it; a time that falls as the pixels grow (noise): nothing.
    share = _pixel_scaling().per_pixel_share
    assert share(110.0, 140.0, 16384, 65536, reference_pixels=16384) == pytest.approx(10 / 110)
    assert share(100.0, 100.0, 16384, 65536) == 0.0
    assert share(100.0, 400.0, 16384, 65536) == pytest.approx(1.0)
    assert share(100.0, 90.0, 16384, 65536) == 0.0


def test_the_share_is_stated_at_the_reference_pixels():
    # Measured at 4096 and 16384 pixels (t = 100 + 10 / 4096 per pixel: 110 and 140 ms), stated at a
    # reference of 16384 pixels: there the growing part is 40 of 140 ms.
    share = _pixel_scaling().per_pixel_share
    assert share(110.0, 140.0, 4096, 16384, reference_pixels=16384) == pytest.approx(40 / 140)
