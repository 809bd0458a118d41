"""SH identities of addon/engine/sh.py, each against an exact answer.

Quadrature: 256 x 512 midpoint cells uniform in cos(theta), so smooth integrands are exact to ~1e-5;
the clamped cosine has a kink at the horizon, which costs ~1e-5 relative. Tolerances are 1e-4.
"""

import numpy as np
import pytest

from addon.engine import sh


@pytest.fixture(scope="module")
def quad():
    return sh.sphere_quadrature()


def test_basis_constants():
    assert sh.Y00 == pytest.approx(0.282095, abs=1e-6)
    assert sh.Y1 == pytest.approx(0.488603, abs=1e-6)
    lobe = sh.cosine_lobe_l1(np.array([0.0, 0.0, 1.0]))
    np.testing.assert_allclose(lobe, [0.886227, 0.0, 1.023327, 0.0], atol=1e-6)


def test_basis_is_orthonormal(quad):
    dirs, w = quad
    b = sh.basis_l2(dirs)
    gram = np.einsum("ki,kj,k->ij", b, b, w)
    np.testing.assert_allclose(gram, np.eye(9), atol=1e-4)


def test_isotropic_radiance_gives_pi_l(quad):
    dirs, w = quad
    radiance = 2.5
    coeffs = sh.project(np.full(len(dirs), radiance), dirs, w)
    for n in ([0, 0, 1], [1, 0, 0], [0.6, -0.8, 0.0]):
        assert sh.irradiance(coeffs, np.array(n, float)) == pytest.approx(np.pi * radiance, rel=1e-4)


@pytest.mark.parametrize(("band", "expected"), [(0, np.pi), (1, 2 * np.pi / 3), (2, np.pi / 4)])
def test_clamped_cosine_band_factors(quad, band, expected):
    # Funk-Hecke: projecting max(0, n.w) gives A_l * Y_lm(n); recover A_l per band.
    dirs, w = quad
    n = np.array([0.0, 0.0, 1.0])
    coeffs = sh.project(np.maximum(dirs @ n, 0.0), dirs, w, order=2)
    basis_n = sh.basis_l2(n)
    idx = [i for i in range(9) if sh.band_of(i) == band and abs(basis_n[i]) > 1e-6]
    for i in idx:
        assert coeffs[i] / basis_n[i] == pytest.approx(expected, rel=1e-4)
    np.testing.assert_allclose(sh.cosine_lobe_l2(n), coeffs, atol=1e-4)


def test_irradiance_of_a_directional_lobe_is_clamped(quad):
    # Radiance concentrated towards +z (a clamped cosine lobe); a normal facing away gets 0, not < 0.
    dirs, w = quad
    coeffs = sh.project(np.maximum(dirs[:, 2], 0.0), dirs, w)
    assert sh.irradiance(coeffs, np.array([0.0, 0.0, -1.0])) == 0.0
    # L = max(0, cos) projects to c_i = A_l Y_i(z), so the L1 irradiance about +z is
    # sum_i (A_l Y_i(z))^2 = 0.886227^2 + 1.023327^2 = 1.8326 (the exact integral is 2 pi / 3 = 2.094;
    # the difference is the truncated band 2 and up).
    exact_l1 = 0.886227**2 + 1.023327**2
    assert sh.irradiance(coeffs, np.array([0.0, 0.0, 1.0])) == pytest.approx(exact_l1, rel=1e-4)


def test_the_irradiance_window_leaks_nothing_opposite_a_single_direction():
    # A unit of radiant intensity from one direction d has the L2 coefficients Y_i(d) and the exact
    # irradiance max(0, n . d): 1 facing it, 0 opposite. Its L2 irradiance lobe(n) . Y(d) is
    # sum_l A_l (2 l + 1) / (4 pi) P_l(n . d): at n = -d 1/4 - 1/2 + 5/16 = 1/16 unwindowed (the floor
    # under a probe that sees a sun patch below it), exactly 0 windowed (1/4 - 0.45 + 0.2).
    # Band 0 is not windowed, so a uniform radiance keeps E = pi L.
    d = np.array([0.36, -0.48, 0.8])
    unit = sh.basis_l2(d)
    assert sh.cosine_lobe_l2(-d) @ unit == pytest.approx(1.0 / 16.0, rel=1e-12)
    assert sh.windowed_cosine_lobe_l2(-d) @ unit == pytest.approx(0.0, abs=1e-15)
    uniform = np.zeros(9)
    uniform[0] = 2.0 * np.sqrt(np.pi)  # L = 1 in every direction
    assert sh.windowed_cosine_lobe_l2(d) @ uniform == pytest.approx(np.pi, rel=1e-12)
