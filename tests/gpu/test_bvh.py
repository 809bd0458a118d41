"""common/bvh.glsl, the sky's exact rays (RsmConfig.sky_rays), against bvh.py's traversal."""

from __future__ import annotations

import numpy as np
import pytest

from addon.engine import bvh, selftest

pytestmark = pytest.mark.gpu


@pytest.mark.parametrize("n", [1, 108, 3000])
def test_the_shader_finds_the_crossings_numpy_finds(gl, n):
    # Random triangles and rays: every answer the same, hit or miss (fp32 on the GPU against float64:
    # the rays are random, so none grazes an edge within rounding but by a chance of about 1e-6 each).
    rng = np.random.default_rng(n)
    tris = rng.random((n, 1, 3)) * 4 + rng.normal(0, 0.2, (n, 3, 3))
    origins = rng.random((3000, 3)) * 4
    directions = rng.normal(size=(3000, 3))
    directions /= np.linalg.norm(directions, axis=1)[:, None]
    tree = bvh.build(tris)
    expected = np.array([bvh.occluded(tree, tris, o, w, 1e-4) for o, w in zip(origins, directions, strict=True)])
    found = selftest.run_bvh_occluded(gl, tris, origins, directions, 1e-4)
    np.testing.assert_array_equal(found, expected)
    assert 0 < expected.sum() < len(expected) or n == 1
