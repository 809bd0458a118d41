"""The LPV transport's numpy twin (addon/engine/lpv_reference.py) on its own, against closed forms.

The GPU passes are tested against it in tests/gpu/test_lpv.py; these check the twin itself. A field's
flux is 2 sqrt(pi) c0 summed, linear in the coefficients, so what is conserved is conserved to float64
rounding (1e-12 relative), or to the precision of the constants used (stated per test).
"""

import numpy as np
import pytest

from addon.engine import lpv_reference as ref
from addon.engine.grid import Grid

GRID = Grid(np.array([-1.0, 0.5, 0.0]), 0.5, (7, 6, 5))


def isotropic(grid, c0=1.0):
    """A field of c0 in every cell and no band 1: each of the six transfers carries c0 / 6 of flux."""
    field = np.zeros((*reversed(grid.dims), 4))
    field[..., 0] = c0
    return field


def test_injection_is_the_lambertian_lobe_in_the_cell_in_front():
    # phi / pi x the clamped-cosine lobe: c0 = phi / (2 sqrt(pi)), band 1 = phi n / sqrt(3 pi), in the
    # cell holding pos + 0.6 h n; its flux is phi. A VPL whose cell is outside the grid is dropped.
    n = np.array([0.48, -0.6, 0.64])
    pos = np.array([[0.3, 1.9, 1.1], [-0.9, 0.6, 0.1]])
    nrm = np.array([n, [-1.0, 0.0, 0.0]])
    field = ref.inject(GRID, pos, nrm, np.array([2.5, 7.0]))
    x, y, z = np.floor((pos[0] + 0.3 * n - GRID.origin_m) / 0.5).astype(int)
    assert (x, y, z) == (2, 2, 2)
    want = np.zeros_like(field)
    want[z, y, x] = 2.5 * np.r_[1.0 / (2.0 * np.sqrt(np.pi)), n[[1, 2, 0]] / np.sqrt(3.0 * np.pi)]
    np.testing.assert_allclose(field, want, rtol=1e-14, atol=0)
    assert ref.flux_w(field) == pytest.approx(2.5, rel=1e-14)


@pytest.mark.parametrize("variant, tolerance", [("gpu", 1e-15), ("classic", 1e-9), ("improved", 2e-5)])
def test_a_step_sends_each_cells_flux_to_its_neighbours(variant, tolerance):
    # One VPL inside the grid: after one step its six neighbours hold its flux. Exact up to the
    # constants: the GPU's form has M00 = 1/6 and cancelling m_cross terms (1e-15); classic's printed
    # solid angles have 10 digits (1e-9); the full quadrature's M00 is 1/6 + 2.2e-6 (6 x: 2e-5).
    mats = ref.gpu_improved_transfer()[0] if variant == "gpu" else ref.transfer_matrices(variant)
    n = np.array([0.6, 0.0, -0.8])
    source = ref.inject(GRID, np.array([[0.7, 1.7, 1.2]]), n[None], np.array([3.0]))
    after = ref.step(source, mats)
    assert np.count_nonzero(after[..., 0]) == 6
    assert ref.flux_w(after) == pytest.approx(3.0, rel=tolerance)


@pytest.mark.parametrize("variant, per_step", [("gpu", 1e-13), ("classic", 2e-10)])
def test_isotropic_field_loses_exactly_what_crosses_the_border(variant, per_step):
    # Each cell sends c0 / 6 of its flux through each face; what leaves through the grid's border is
    # lost, nothing else: flux after = flux x (1 - border faces / (6 cells)). Periodic on every axis,
    # nothing leaves over 20 steps. Tolerance per step: float64 sums, or classic's solid angles, whose
    # printed 10 digits sum to 4 pi within 1e-10.
    mats = ref.gpu_improved_transfer()[0] if variant == "gpu" else ref.transfer_matrices(variant)
    field = isotropic(GRID)
    nx, ny, nz = GRID.dims
    border_faces = 2 * (ny * nz + nx * nz + nx * ny)
    want = ref.flux_w(field) * (1.0 - border_faces / (6.0 * nx * ny * nz))
    assert ref.flux_w(ref.step(field, mats)) == pytest.approx(want, rel=per_step)
    current = field
    for _ in range(20):
        current = ref.step(current, mats, periodic_axes=(0, 1, 2))
    assert ref.flux_w(current) == pytest.approx(ref.flux_w(field), rel=20 * per_step)


def test_a_wall_on_a_cell_face_stops_the_transfer_across_it():
    # A wall of projected area 1.5 cells^2 along x (blocking saturates at 1) in the cells x = 3, lying on
    # their +x face (offset +0.5 cells): closed both ways across that face, open elsewhere. Light
    # starting at x <= 3 never reaches x >= 4 (exactly 0 after 12 steps). Without surface offsets the
    # wall cell's blocking splits half and half: light entering it and leaving it pass 0.5 each.
    shape = (*reversed(GRID.dims), 4)
    projected, offset = np.zeros(shape), np.zeros(shape)
    projected[:, :, 3, 0] = 1.5
    offset[:, :, 3, 0] = 0.5
    through = ref.pass_through(*ref.blocking(projected, offset))
    plus_x, minus_x = through[0], through[1]  # AXES order: +x, -x, ...
    assert np.all(plus_x[:, :, 4] == 0.0) and np.all(minus_x[:, :, 3] == 0.0)
    assert np.all(plus_x[:, :, 3] == 1.0) and np.all(minus_x[:, :, 2] == 1.0)  # the wall's other face
    field = isotropic(GRID)
    field[:, :, 4:] = 0.0
    mats, path = ref.gpu_improved_transfer()
    acc = ref.accumulate(field, mats, path, 12, through)
    assert np.all(acc[:, :, 4:] == 0.0) and np.abs(acc[:, :, :4, 0]).min() > 0.0
    half_and_half = ref.pass_through(*ref.blocking(projected))
    assert np.all(half_and_half[0][:, :, 3] == 0.5) and np.all(half_and_half[0][:, :, 4] == 0.5)


def test_lookup_of_uniform_light_travelling_down():
    # Every cell holds a / pi x lobe(-z), light travelling down. A receiver facing up reads
    # max(0, c . lobe(-n)) / (h^2 pi) = a (pi/4 + pi/3) / (h^2 pi^2) = 7 a / (12 pi h^2); one facing down
    # reads the negative back lobe, clamped to 0. The geometry-aware weights are renormalised, so on a
    # uniform field any geometry volume reads the same, and one blocking every corner falls back to plain
    # trilinear. float64: 1e-12.
    a, h = 3.0, GRID.cell_size_m
    acc = np.broadcast_to(a / np.pi * np.r_[np.sqrt(np.pi) / 2, 0.0, -np.sqrt(np.pi / 3), 0.0],
                          (*reversed(GRID.dims), 4))
    rng = np.random.default_rng(4)
    pos = GRID.origin_m + rng.uniform(0, 1, (20, 3)) * GRID.extent_m
    up, down = np.tile([0.0, 0.0, 1.0], (20, 1)), np.tile([0.0, 0.0, -2.0], (20, 1))
    want = 7.0 * a / (12.0 * np.pi * h * h)
    np.testing.assert_allclose(ref.lookup(acc, GRID, pos, up), want, rtol=1e-12)
    assert np.all(ref.lookup(acc, GRID, pos, down) == 0.0)
    vox_normal = np.concatenate([rng.normal(size=acc.shape[:3] + (3,)), rng.uniform(0, 2, acc.shape[:3] + (1,))],
                                axis=-1)
    np.testing.assert_allclose(ref.lookup(acc, GRID, pos, up, vox_normal), want, rtol=1e-12)
    walled = np.broadcast_to([0.0, 0.0, 1.0, 1.0], acc.shape)
    np.testing.assert_allclose(ref.lookup(acc, GRID, pos, up, walled), want, rtol=1e-12)
