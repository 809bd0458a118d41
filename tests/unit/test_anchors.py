"""addon/bridge/anchors.py without Blender: the Cycles + OIDN step on a synthetic noisy pass.

The exact answer is a constant pass of 0.5 (light / Diffuse Color, as Cycles writes it) under a constant
albedo of 0.8; the noisy input is that constant times gamma noise of mean 1 and relative standard
deviation 0.5 (a positive Monte Carlo estimate, about a 4-spp Diffuse Indirect pixel), fixed seed.
Measured with pyoidn 2.5.1 over seeds 0-2: the denoised mean is within 1.2 % of 0.5 (the noisy mean's own
standard error over 64 x 56 x 3 values is 0.45 %) and rel_rmse falls from 0.50 to 0.026-0.031.
"""

import numpy as np
import pytest

from addon.engine.metrics import rel_rmse

pytest.importorskip("pyoidn")
from addon.bridge import anchors  # noqa: E402  (after the skip: the module needs pyoidn to run)

TRUTH = 0.5
ALBEDO = 0.8
REL_STD = 0.5
MEAN_TOL = 0.02  # 1.7x the largest deviation measured over three seeds: OIDN's weights may change by release
MIN_GAIN = 5.0  # rel_rmse must fall at least 5x (measured 16-19x): a denoiser that barely helps fails
BLACK_COLUMNS = 8  # an emitter's black panel: Diffuse Color 0, where Cycles' pass is 0


def _inputs(seed=0, h=64, w=64):
    rng = np.random.default_rng(seed)
    k = 1 / REL_STD**2  # gamma(k, 1/k): mean 1, standard deviation 1/sqrt(k)
    noisy = (TRUTH * rng.gamma(k, 1 / k, (h, w, 3))).astype(np.float32)
    albedo = np.full((h, w, 3), ALBEDO, np.float32)
    albedo[:, :BLACK_COLUMNS] = 0.0
    noisy[:, :BLACK_COLUMNS] = 0.0
    normal = np.zeros((h, w, 3), np.float32)
    normal[..., 2] = 1.0
    return noisy, albedo, normal


def test_oidn_keeps_the_mean_and_removes_the_noise():
    noisy, albedo, normal = _inputs()
    lit = albedo[:, :, 0] > 0
    truth = np.full_like(noisy, TRUTH)
    image, seconds = anchors.timed_denoise(noisy, albedo, normal)
    assert image.shape == noisy.shape and image.dtype == np.float32
    assert seconds > 0
    assert image[lit].mean() == pytest.approx(TRUTH, rel=MEAN_TOL)
    before, after = rel_rmse(noisy, truth, lit), rel_rmse(image, truth, lit)
    assert before == pytest.approx(REL_STD, rel=0.05)  # the input is as noisy as stated (12288 draws)
    assert after * MIN_GAIN <= before, (before, after)
    assert np.all(image[~lit] == 0.0)  # no albedo: the pass is 0, as Cycles writes it


def test_oidn_returns_pass_units_whatever_the_albedo():
    """The pass is light / albedo: the same pass under a darker albedo must come back the same, which
    fails if the division by the albedo after denoising is missing or wrong."""
    noisy, albedo, normal = _inputs()
    lit = albedo[:, :, 0] > 0
    bright = anchors.denoise_light(noisy, albedo, normal)
    dark = anchors.denoise_light(noisy, albedo * 0.25, normal)
    assert dark[lit].mean() == pytest.approx(bright[lit].mean(), rel=MEAN_TOL)
    assert dark[lit].mean() == pytest.approx(TRUTH, rel=MEAN_TOL)
