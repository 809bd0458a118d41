"""Voxelization against exact cell sets: conservative coverage leaves no holes and over-covers by at
most the cells a triangle touches; values are area-weighted means."""

import numpy as np
import pytest

from addon.engine.grid import Grid
from addon.engine.passes.voxelize import Voxelizer
from addon.engine.scene import Scene

pytestmark = pytest.mark.gpu


def scene(tris, albedo):
    tris = np.asarray(tris, np.float32)
    n = len(tris)
    return Scene(tris, np.zeros_like(tris), np.asarray(albedo, np.float32).reshape(n, 3), np.zeros((n, 3), np.float32))


def voxelize(gl, sc, grid):
    v = Voxelizer(gl, grid)
    v.set_scene(sc)
    vols = v.run()
    return {k: gl.read(t) for k, t in vols.items()}


def cells_touched(tri, samples=200_000, seed=0):
    """Cells containing dense random points of the triangle (the cells it certainly occupies)."""
    r = np.random.default_rng(seed).random((samples, 2))
    flip = r.sum(axis=1) > 1
    r[flip] = 1 - r[flip]
    p = tri[0] + r[:, :1] * (tri[1] - tri[0]) + r[:, 1:] * (tri[2] - tri[0])
    return set(map(tuple, np.floor(p).astype(int)))


def distance_to_triangle_cells(tri, cell):
    """Smallest distance between cell [c, c+1)^3 and points of the triangle (dense sampling)."""
    r = np.random.default_rng(1).random((50_000, 2))
    flip = r.sum(axis=1) > 1
    r[flip] = 1 - r[flip]
    p = tri[0] + r[:, :1] * (tri[1] - tri[0]) + r[:, 1:] * (tri[2] - tri[0])
    c = np.asarray(cell, float)
    d = np.maximum(np.maximum(c - p, p - (c + 1)), 0.0)
    return float(np.sqrt((d * d).sum(axis=1)).min())


@pytest.mark.parametrize(
    "tri",
    [
        [[0.1, 0.2, 0.3], [7.7, 1.1, 0.9], [1.3, 7.6, 6.2]],  # slanted, large
        [[0.5, 0.5, 0.5], [7.5, 7.4, 7.6], [0.6, 0.4, 0.7]],  # long and thin (grazing from every axis)
        [[3.2, 3.3, 3.4], [3.6, 3.5, 3.7], [3.3, 3.8, 3.5]],  # smaller than a cell
    ],
)
def test_conservative_coverage(gl, tri):
    tri = np.array(tri)
    vols = voxelize(gl, scene([tri], [[0.5, 0.5, 0.5]]), Grid(np.zeros(3), 1.0, (8, 8, 8)))
    occupied = {(x, y, z) for z, y, x in np.argwhere(vols["vox_albedo"][..., 3] > 0)}
    touched = cells_touched(tri)
    assert touched - occupied == set()  # no holes
    # Over-coverage is bounded: a conservative rasterizer may add cells within half a cell diagonal.
    for cell in occupied - touched:
        assert distance_to_triangle_cells(tri, cell) <= 0.87


def test_closed_box_shell(gl):
    # A 4 x 4 x 4 box with faces at cell centres (z = 2.5 ... 6.5) occupies exactly its shell:
    # 5^3 - 3^3 = 98 cells of the 5 x 5 x 5 block of cells it spans.
    lo, hi = 2.5, 6.5
    corners = np.array([[x, y, z] for x in (lo, hi) for y in (lo, hi) for z in (lo, hi)])
    quads = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
    tris = [[corners[q[0]], corners[q[i]], corners[q[i + 1]]] for q in quads for i in (1, 2)]
    vols = voxelize(gl, scene(tris, [[0.5] * 3] * 12), Grid(np.zeros(3), 1.0, (9, 9, 9)))
    occ = vols["vox_albedo"][..., 3] > 0
    expected = np.zeros((9, 9, 9), bool)
    expected[2:7, 2:7, 2:7] = True
    expected[3:6, 3:6, 3:6] = False
    np.testing.assert_array_equal(occ, expected)


def test_values_are_area_weighted_means(gl):
    # Two axis-aligned triangles inside cell (1, 1, 1): areas 0.5 * 0.8^2 = 0.32 and 0.5 * 0.4^2 = 0.08
    # with albedo 1 and 0 -> mean 0.32 / 0.40 = 0.8; normals +z and +x -> mean direction (0.08, 0, 0.32)
    # normalised.
    t1 = [[1.1, 1.1, 1.5], [1.9, 1.1, 1.5], [1.1, 1.9, 1.5]]  # normal +z
    t2 = [[1.5, 1.1, 1.1], [1.5, 1.5, 1.1], [1.5, 1.1, 1.5]]  # normal +x
    vols = voxelize(gl, scene([t1, t2], [[1, 1, 1], [0, 0, 0]]), Grid(np.zeros(3), 1.0, (3, 3, 3)))
    np.testing.assert_allclose(vols["vox_albedo"][1, 1, 1], [0.8, 0.8, 0.8, 1.0], atol=1e-5)
    n = np.array([0.08, 0.0, 0.32])
    np.testing.assert_allclose(vols["vox_normal"][1, 1, 1, :3], n / np.linalg.norm(n), atol=1e-5)
    assert vols["vox_albedo"][..., 3].sum() == 1.0


def test_grid_fit_is_not_cubic_for_flat_scenes():
    g = Grid.fit(np.array([0.0, 0.0, 0.0]), np.array([100.0, 50.0, 1.0]), max_cells=64)
    # 1.5 cells of padding per side: cell = 100 / (64 - 3) m; y: 50 / cell + 3 -> 34; z: 1 / cell + 3 -> 4.
    assert g.dims == (64, 34, 4)
    lo, hi = g.origin_m, g.origin_m + g.extent_m
    assert np.all(lo <= [0, 0, 0]) and np.all(hi >= [100, 50, 1])


def test_slab_buckets_change_nothing(gl, monkeypatch):
    """Drawing each slab's bucket (slab_triangles) gives exactly the volumes of drawing every triangle
    into every slab: 3000 random triangles of every size and slope, 40-cell grid (measured: equal to
    the bit; additive blending of the same fragments in the same order)."""
    from addon.engine.passes import voxelize as vox

    rng = np.random.default_rng(1)
    centres = rng.random((3000, 1, 3)) * 10
    tris = centres + rng.normal(size=(3000, 3, 3)) * rng.random((3000, 1, 1)) * 1.5
    sc = scene(tris, rng.random((3000, 3)))
    grid = Grid.fit(*sc.bounds_m(), max_cells=40)
    bucketed = voxelize(gl, sc, grid)
    monkeypatch.setattr(vox, "slab_triangles", lambda p, g, axis: {k: np.arange(len(p)) for k in range(g.dims[axis])})
    everything = voxelize(gl, sc, grid)
    for key in bucketed:
        np.testing.assert_array_equal(bucketed[key], everything[key], err_msg=key)
    assert np.count_nonzero(bucketed["vox_albedo"][..., 3]) > 10_000


def test_projected_area_counts_a_closed_object_once(gl):
    """A closed axis-aligned cube of side 0.5 inside cell (1, 1, 1): along each axis its faces facing +
    and - each project 0.25 cell^2, its silhouette; the opacity area is max(P+, P-) = 0.25 (the sum of
    |n| gave 0.5). A lone quad facing +x (0.6 x 0.6) keeps its whole area 0.36 along x and 0 along y, z.
    Exact up to fp32 sums of a few fragments (atol 1e-5)."""
    lo, hi = 1.25, 1.75
    corners = np.array([[x, y, z] for x in (lo, hi) for y in (lo, hi) for z in (lo, hi)])
    quads = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
    tris = [[corners[q[0]], corners[q[i]], corners[q[i + 1]]] for q in quads for i in (1, 2)]
    vols = voxelize(gl, scene(tris, [[0.5] * 3] * 12), Grid(np.zeros(3), 1.0, (3, 3, 3)))
    np.testing.assert_allclose(vols["vox_projected"][1, 1, 1, :3], [0.25, 0.25, 0.25], atol=1e-5)
    quad = [[[1.5, 1.2, 1.2], [1.5, 1.8, 1.2], [1.5, 1.8, 1.8]], [[1.5, 1.2, 1.2], [1.5, 1.8, 1.8], [1.5, 1.2, 1.8]]]
    vols = voxelize(gl, scene(quad, [[0.5] * 3] * 2), Grid(np.zeros(3), 1.0, (3, 3, 3)))
    np.testing.assert_allclose(vols["vox_projected"][1, 1, 1, :3], [0.36, 0.0, 0.0], atol=1e-5)
