"""bvh.py: the hierarchy the sky's exact rays traverse (its GPU traversal: tests/gpu/test_bvh.py)."""

from __future__ import annotations

import numpy as np
import pytest

from addon.engine import bvh


def random_triangles(n: int, seed: int = 0) -> np.ndarray:
    rng = np.random.default_rng(seed)
    return rng.random((n, 1, 3)) * 4 + rng.normal(0, 0.2, (n, 3, 3))


@pytest.mark.parametrize("n", [0, 1, 4, 5, 300])
def test_every_triangle_lies_in_one_leaf_within_every_box_above_it(n):
    tris = random_triangles(n)
    tree = bvh.build(tris)
    assert sorted(tree.order.tolist()) == list(range(n))
    assert tree.leaves * bvh.LEAF_TRIANGLES >= n and tree.leaves & (tree.leaves - 1) == 0
    for slot, t in enumerate(tree.order):
        node = tree.leaves - 1 + slot // bvh.LEAF_TRIANGLES
        while True:  # the leaf and each node above it holds the triangle's corners
            assert np.all(tris[t] >= tree.lo[node]) and np.all(tris[t] <= tree.hi[node])
            if node == 0:
                break
            node = (node - 1) // 2


def test_the_traversal_finds_exactly_the_crossings_of_a_search_of_every_triangle():
    tris = random_triangles(300, seed=1)
    tree = bvh.build(tris)
    rng = np.random.default_rng(2)
    hits = 0
    for _ in range(400):
        q = rng.random(3) * 4
        w = rng.normal(size=3)
        w /= np.linalg.norm(w)
        brute = any(bvh.segment_crosses(t, q, w, 1e-4, np.inf) for t in tris)
        assert bvh.occluded(tree, tris, q, w, 1e-4) == brute
        hits += brute
    assert 50 < hits < 350  # both answers are exercised


def test_the_tables_hold_the_nodes_and_the_triangles_in_leaf_order():
    tris = random_triangles(9)
    tree = bvh.build(tris)  # 3 leaves of 4 -> 4 leaves, the last empty
    nodes = bvh.node_table(tree).reshape(-1, 2, 4)
    np.testing.assert_allclose(nodes[0, 0, :3], tris.reshape(-1, 3).min(axis=0), rtol=1e-6)
    np.testing.assert_allclose(nodes[0, 1, :3], tris.reshape(-1, 3).max(axis=0), rtol=1e-6)
    empty = tree.nodes - 1  # the last leaf: low x above high x, which the traversal skips
    assert nodes[empty, 0, 0] > nodes[empty, 1, 0]
    leaf_order = bvh.leaf_triangles(tree, tris)
    np.testing.assert_array_equal(leaf_order[:9], tris[tree.order])
    assert not leaf_order[9:].any()  # empty slots have no area: no ray crosses them


def test_a_ray_along_a_triangles_plane_or_behind_its_start_does_not_cross_it():
    tri = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0]])
    up = np.array([0.0, 0, 1])
    assert bvh.segment_crosses(tri, np.array([0.2, 0.2, -1]), up, 0.0, np.inf)
    assert not bvh.segment_crosses(tri, np.array([0.2, 0.2, 1]), up, 0.0, np.inf)  # behind the start
    assert not bvh.segment_crosses(tri, np.array([0.2, 0.2, -1]), up, 1.5, np.inf)  # nearer than s_min
    assert not bvh.segment_crosses(tri, np.array([-1, 0.2, 0]), np.array([1.0, 0, 0]), 0.0, np.inf)
