"""tools/diffusion_dark_pixels.py's measures on inputs whose answer is known."""

import importlib.util
from pathlib import Path

import numpy as np

from addon.engine.grid import Grid

ROOT = Path(__file__).resolve().parents[2]
_spec = importlib.util.spec_from_file_location("diffusion_dark_pixels", ROOT / "tools" / "diffusion_dark_pixels.py")
dark_pixels = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(dark_pixels)


def test_a_dark_pixel_reads_under_a_tenth_of_a_lit_reference():
    # Reference 1..10 over ten covered pixels (30th percentile 3.7) and one uncovered; ours: a tenth of
    # it exactly is not dark (<), just under is; below the percentile nothing is dark.
    ref = np.array([1.0, 2, 3, 4, 5, 6, 7, 8, 9, 10, 50])
    ours = np.array([0.0, 0.0, 0.0, 0.4, 0.49, 1.0, 7.0, 0.0, 0.89, 0.99, 0.0])
    covered = np.array([True] * 10 + [False])
    assert np.flatnonzero(dark_pixels.dark_mask(ours, ref, covered)).tolist() == [4, 7, 8, 9]


def cells(normal, mask_bits):
    """A 2 x 2 x 2 grid of 1 m cells at the origin, every cell occupied with the given plane normal and
    cell_block.w = 1 + mask_bits (diffusion/cell.glsl)."""
    block = np.zeros((2, 2, 2, 4), np.float32)
    block[..., 3] = 1 + mask_bits
    plane = np.zeros((2, 2, 2, 4), np.float32)
    plane[..., :3] = normal
    return Grid(np.zeros(3), 1.0, (2, 2, 2)), block, plane


def test_the_alignment_is_the_best_cosine_over_the_receiving_sides_read():
    point = np.array([[1.0, 1.0, 1.0]])  # the corner all 8 cells share: the lookup reads them all
    n = np.array([[0.6, 0.0, 0.8]])  # . (0, 0, 1) = 0.8 exactly, in float64 as the tool computes it
    grid, block, plane = cells([0.0, 0.0, 1.0], dark_pixels.RECEIVES_PLUS)
    assert dark_pixels.best_alignment(point, n, grid, block, plane)[0] == 0.8
    # The pixel faces the minus side (n . n_cell < 0), which no light reaches: no cell counts.
    assert dark_pixels.best_alignment(point, -n, grid, block, plane)[0] == 0.0
    grid, block, plane = cells([0.0, 0.0, 1.0], dark_pixels.RECEIVES_MINUS)
    assert dark_pixels.best_alignment(point, -n, grid, block, plane)[0] == 0.8
    block[..., 3] = 0.0  # no cell holds a surface
    assert dark_pixels.best_alignment(point, n, grid, block, plane)[0] == 0.0
