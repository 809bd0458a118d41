"""The denoise pass (passes/denoise.py) gives the same numbers on Blender's gpu module as on moderngl."""

import sys
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("bpy")

pytestmark = [pytest.mark.blender, pytest.mark.gpu]

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "gpu"))
from test_denoise import floor_and_sphere, on_gpu  # noqa: E402

from addon.engine.passes import denoise  # noqa: E402


@pytest.mark.parametrize("iterations", [1, 4])
def test_blender_gpu_denoise_equals_moderngl(gl, blender_backend, iterations):
    # Odd and even iteration counts: the ping-pong ends in `out` from either texture. Same GLSL body,
    # same Mesa llvmpipe and fp32 maths on both: equal to float32 rounding.
    rng = np.random.default_rng(7)
    pos, nrm = floor_and_sphere()
    noisy = rng.uniform(0.0, 2.0, pos.shape) * pos[..., 3:]
    params = denoise.Params(iterations=iterations)
    a = on_gpu(gl, pos, nrm, noisy, params)
    b = on_gpu(blender_backend, pos, nrm, noisy, params)
    assert np.abs(a - noisy).max() > 0.1  # the filter did something
    np.testing.assert_allclose(b, a, rtol=1e-5, atol=1e-6)
