"""tools/dark_room_leak.py's measure on images whose answer is known."""

import importlib.util
import math
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
_spec = importlib.util.spec_from_file_location("dark_room_leak", ROOT / "tools" / "dark_room_leak.py")
dark_room_leak = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(dark_room_leak)


def two_rooms(dark_value: float, lit_value: float = 2.0) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A 4 x 8 image: columns 0-3 the lit room (reference light 1), 4-7 the dark one (reference 0), one
    uncovered row; ours holds lit_value and dark_value per channel."""
    reference = np.zeros((4, 8, 4))
    reference[..., 3] = 1.0
    reference[3, :, 3] = 0.0  # not covered: ignored whatever it holds
    reference[:, :4, :3] = 1.0
    ours = np.zeros((4, 8, 4))
    ours[:, :4, :3] = lit_value
    ours[:, 4:, :3] = dark_value
    ours[3, :, :3] = 100.0
    return reference, reference.copy(), ours


def test_the_leak_is_the_dark_rooms_light_over_the_lit_rooms():
    direct, indirect, ours = two_rooms(dark_value=0.25)
    assert dark_room_leak.leak(direct, indirect, ours) == (12, 0.125)  # 0.25 / 2, exact in binary
    direct, indirect, ours = two_rooms(dark_value=0.0)
    assert dark_room_leak.leak(direct, indirect, ours) == (12, 0.0)


def test_a_pixel_with_direct_light_only_is_not_dark():
    direct, indirect, ours = two_rooms(dark_value=0.0)
    indirect[:, :4, :3] = 0.0  # the lit room's indirect 0, its direct still 1
    assert dark_room_leak.leak(direct, indirect, ours)[0] == 12


def test_no_dark_pixels_gives_nan():
    direct, indirect, ours = two_rooms(dark_value=0.0)
    direct[..., :3] = 1.0
    assert math.isnan(dark_room_leak.leak(direct, indirect, ours)[1])
