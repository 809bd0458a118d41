"""Scene.prepared(): what the GPU passes receive."""

import numpy as np

from addon.engine.scene import Scene, first_copies


def test_first_copies_ignores_corner_order_and_winding():
    """A triangle repeated as-is, rotated and with its winding reversed is one surface: only its first
    occurrence is kept. A triangle differing in one coordinate by one ulp is another triangle."""
    rng = np.random.default_rng(0)
    t = rng.random((4, 3, 3))
    other = t[:1].copy()
    other[0, 2, 1] = np.nextafter(other[0, 2, 1], 2.0)
    tris = np.concatenate([t, t[:, [1, 2, 0]], t[:, [0, 2, 1]], other])
    np.testing.assert_array_equal(first_copies(tris), [True] * 4 + [False] * 8 + [True])
    assert first_copies(np.zeros((0, 3, 3))).shape == (0,)


def test_prepared_drops_duplicates_with_a_warning():
    tri = np.array([[[0, 0, 0], [1, 0, 0], [0, 1, 0]]], np.float32)
    tris = np.concatenate([tri, tri, tri[:, ::-1], tri + 2.0])
    n = len(tris)
    scene = Scene(tris, np.zeros_like(tris), np.full((n, 3), 0.5, np.float32), np.zeros((n, 3), np.float32))
    local, _ = scene.prepared()
    assert local.triangle_count == 2
    assert any("2 duplicated triangles" in w for w in local.warnings)
