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
    """Drawing each slab's bucket (slab_range) gives exactly the volumes of drawing every triangle
    into every slab: 3000 random triangles of every size and slope, 40-cell grid (measured: equal to
    the bit; additive blending of the same fragments in the same order)."""
    from addon.engine.passes import voxelize as vox

    rng = np.random.default_rng(1)
    centres = rng.random((3000, 1, 3)) * 10
    tris = centres + rng.normal(size=(3000, 3, 3)) * rng.random((3000, 1, 1)) * 1.5
    sc = scene(tris, rng.random((3000, 3)))
    grid = Grid.fit(*sc.bounds_m(), max_cells=40)
    bucketed = voxelize(gl, sc, grid)
    monkeypatch.setattr(vox, "slab_range", lambda p, g, axis: (np.zeros(len(p), np.int64),
                                                               np.full(len(p), g.dims[axis] - 1, np.int64)))
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


def quad_x(x, lo=1.2, hi=1.8):
    """Two triangles of a square facing +x at depth x over y, z in [lo, hi]."""
    return [[[x, lo, lo], [x, hi, lo], [x, hi, hi]], [[x, lo, lo], [x, hi, hi], [x, lo, hi]]]


def test_surface_offset_is_where_the_surface_lies_in_its_cell(gl):
    """vox_offset: per axis the area-weighted mean offset, from the cell's centre in cells, of the
    surfaces voxelized along that axis. A square facing +x at x = 1.8 in cell (1, 1, 1): 0.3 along x, 0
    along y and z (no surface is voxelized along them). Two squares, at 1.2 (area 0.36) and 1.7 (area
    0.16, a smaller square): (0.36 * -0.3 + 0.16 * 0.2) / 0.52 = -0.14615. A square on the cell's face
    x = 2 lies in one of the two cells only; no other offset may leave -0.5..0.5. Exact up to fp32 sums
    of a few fragments (atol 1e-5)."""
    grid = Grid(np.zeros(3), 1.0, (3, 3, 3))
    vols = voxelize(gl, scene(quad_x(1.8), [[0.5] * 3] * 2), grid)
    np.testing.assert_allclose(vols["vox_offset"][1, 1, 1, :3], [0.3, 0.0, 0.0], atol=1e-5)
    two = quad_x(1.2) + quad_x(1.7, 1.3, 1.7)
    vols = voxelize(gl, scene(two, [[0.5] * 3] * 4), grid)
    np.testing.assert_allclose(vols["vox_offset"][1, 1, 1, 0], (0.36 * -0.3 + 0.16 * 0.2) / 0.52, atol=1e-5)
    np.testing.assert_allclose(vols["vox_normal"][1, 1, 1, 3], 0.52, atol=1e-5)  # the weights divided by
    assert np.all(vols["vox_offset"][vols["vox_albedo"][..., 3] == 0] == 0.0)
    assert np.all(np.abs(vols["vox_offset"]) <= 0.5)


def test_surface_area_is_exact_for_finely_tessellated_and_partial_surfaces(gl):
    """The weight of a fragment is the triangle's area clipped to its cell, so a surface's area per cell
    does not depend on how it is tessellated, and a surface covering part of a cell counts that part.
    A 3 x 3 square over x, y in [0.5, 3.5] at z = 1.5, cut into 2 x 18 x 18 triangles whose edges cross
    every cell: area 1 in the cells it covers, 0.5 in those it half covers, 0.25 in its corners (before
    the clipping every pixel a triangle grazed weighed a whole pixel; this test then failed by 0.49).
    atol 1e-4: fp32 sums of up to ~100 fragments. A quad tilted by atan(0.4) over x, y in [0.25, 2.25]:
    each cell's area is its exact share, integrated numerically here (4e6 samples: atol 2e-3)."""
    n = 18
    xs = 0.5 + 3.0 * np.arange(n + 1) / n
    tris = []
    for i in range(n):
        for j in range(n):
            a, b = [xs[i], xs[j], 1.5], [xs[i + 1], xs[j], 1.5]
            c, d = [xs[i + 1], xs[j + 1], 1.5], [xs[i], xs[j + 1], 1.5]
            tris += [[a, b, c], [a, c, d]]
    vols = voxelize(gl, scene(tris, [[0.5] * 3] * len(tris)), Grid(np.zeros(3), 1.0, (4, 4, 4)))
    area = vols["vox_normal"][..., 3]
    share = np.array([0.5, 1.0, 1.0, 0.5])
    np.testing.assert_allclose(area[1], np.outer(share, share), atol=1e-4)
    assert area.sum() == pytest.approx(9.0, abs=1e-3)
    # A tilted quad: z = 1.2 + 0.4 x over x, y in [0.25, 2.25] (normal dominant along z).
    def z_of(x):
        return 1.2 + 0.4 * x
    quad = np.array([[0.25, 0.25], [2.25, 0.25], [2.25, 2.25], [0.25, 2.25]])
    corners = [[x, y, z_of(x)] for x, y in quad]
    tilted = [[corners[0], corners[1], corners[2]], [corners[0], corners[2], corners[3]]]
    vols = voxelize(gl, scene(tilted, [[0.5] * 3] * 2), Grid(np.zeros(3), 1.0, (3, 3, 3)))
    # Expected area per cell: sample the quad finely (surface element sqrt(1 + 0.4^2) per unit of x, y).
    u = (np.arange(2000) + 0.5) / 2000 * 2.0 + 0.25
    x, y = np.meshgrid(u, u, indexing="ij")
    cells = np.stack([np.floor(x), np.floor(y), np.floor(z_of(x))], axis=-1).astype(int).reshape(-1, 3)
    expected = np.zeros((3, 3, 3))
    np.add.at(expected, (cells[:, 2], cells[:, 1], cells[:, 0]), (2.0 / 2000) ** 2 * np.sqrt(1 + 0.4**2))
    np.testing.assert_allclose(vols["vox_normal"][..., 3], expected, atol=2e-3)


# Incremental re-voxelization (Voxelizer.update). Why each result is exact: a layer that is not redrawn
# holds only unchanged triangles, drawn from the same mesh as before; a redrawn layer gets the triangles
# a full set_scene gives it, in the same order, and additive blending of the same fragments in the same
# (primitive) order gives the same bits. So every comparison below is np.array_equal, no tolerance.

INCREMENTAL_GRID = Grid(np.zeros(3), 1.0, (16, 16, 16))


def box(lo, hi):
    """12 outward-wound triangles of the axis-aligned box [lo, hi]."""
    corners = np.array([[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])])
    quads = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
    return [[corners[q[0]], corners[q[i]], corners[q[i + 1]]] for q in quads for i in (1, 2)]


def boxes_scene(small_box_lo=(3.3, 3.2, 3.4)):
    """A floor quad at z = 0.5 (triangles 0, 1), a large box (2..13), an emissive small box (14..25)."""
    floor = [[[0.5, 0.5, 0.5], [15.5, 0.5, 0.5], [15.5, 15.5, 0.5]],
             [[0.5, 0.5, 0.5], [15.5, 15.5, 0.5], [0.5, 15.5, 0.5]]]
    small_lo = np.asarray(small_box_lo)
    tris = np.array(floor + box((8.2, 7.6, 0.5), (13.4, 12.7, 6.3)) + box(small_lo, small_lo + 1.6), np.float32)
    n = len(tris)
    albedo = np.tile(np.float32([[0.8, 0.8, 0.8]]), (n, 1))
    albedo[2:14] = [0.2, 0.6, 0.3]
    emission = np.zeros((n, 3), np.float32)
    emission[14:] = [4.0, 2.0, 1.0]
    return Scene(tris, np.zeros_like(tris), albedo, emission)


def incremental(gl, before, after):
    """Voxelize `before` fully, then `after` through update: (volumes, changed triangles, layers drawn)."""
    v = Voxelizer(gl, INCREMENTAL_GRID)
    v.set_scene(before)
    v.run()
    assert v.layers_drawn == sum(INCREMENTAL_GRID.dims)
    changed = v.update(after)
    vols = v.run()
    return {k: gl.read(t) for k, t in vols.items()}, changed, v.layers_drawn


def assert_volumes_equal(got, expected):
    for key in expected:
        assert np.array_equal(got[key], expected[key]), key


def test_incremental_moved_box_equals_full_voxelization(gl):
    """Moving the small box redraws only the slabs its faces reached before or reach now, and the
    result is bitwise that of voxelizing the moved scene from scratch (why exact: see above)."""
    before, after = boxes_scene(), boxes_scene(small_box_lo=(4.1, 3.2, 3.9))
    vols, changed, layers = incremental(gl, before, after)
    expected = voxelize(gl, after, INCREMENTAL_GRID)
    assert not np.array_equal(expected["vox_albedo"], voxelize(gl, before, INCREMENTAL_GRID)["vox_albedo"])
    assert_volumes_equal(vols, expected)
    assert changed == 12
    # Box [3.3, 4.9] -> [4.1, 5.7] along x: x faces reach layers 2..5 and 3..6; y faces (3.2 -> 3.2 + 1.6,
    # unchanged along y) layers 2..5; z faces [3.4, 5.0] -> [3.9, 5.5]: layers 2..6 and 2..6.
    assert layers == 5 + 4 + 5
    assert layers < sum(INCREMENTAL_GRID.dims)


def test_incremental_albedo_change_redraws_its_slabs_only(gl):
    """Changing one floor triangle's albedo redraws the two z layers it reaches (z = 0.5 widened by a
    cell: layers 0 and 1); exact because those layers get the same triangle list, the rest is untouched."""
    before = boxes_scene()
    after = boxes_scene()
    after.albedo[0] = [0.1, 0.9, 0.4]
    vols, changed, layers = incremental(gl, before, after)
    assert_volumes_equal(vols, voxelize(gl, after, INCREMENTAL_GRID))
    assert not np.array_equal(vols["vox_albedo"], voxelize(gl, before, INCREMENTAL_GRID)["vox_albedo"])
    assert (changed, layers) == (1, 2)


def test_incremental_nothing_changed_draws_nothing(gl):
    """An identical scene changes no triangle: no layer is redrawn, and the volumes (untouched axis
    volumes merged again by the same deterministic compute pass) equal the full voxelization."""
    vols, changed, layers = incremental(gl, boxes_scene(), boxes_scene())
    assert (changed, layers) == (0, 0)
    assert_volumes_equal(vols, voxelize(gl, boxes_scene(), INCREMENTAL_GRID))


def test_incremental_other_triangle_count_falls_back(gl):
    """Removing the small box leaves no row correspondence: update falls back to set_scene and the run
    redraws every layer, which is a full voxelization (the same code path, so exact)."""
    before = boxes_scene()
    after = Scene(before.positions_m[:14], before.normals[:14], before.albedo[:14], before.emission[:14])
    vols, changed, layers = incremental(gl, before, after)
    assert (changed, layers) == (14, sum(INCREMENTAL_GRID.dims))
    assert_volumes_equal(vols, voxelize(gl, after, INCREMENTAL_GRID))


def test_incremental_dominant_axis_change_dirties_both_axes(gl):
    """The small box's top face triangle (normal +z, in z layers) rotated to face +x (drawn along x)
    must leave the z layers it reached and enter the x layers it reaches: both are redrawn, and the
    result is exact (same triangle lists per redrawn layer, the others untouched)."""
    before = boxes_scene()
    top = next(i for i in range(14, 26)
               if np.allclose(before.positions_m[i][:, 2], before.positions_m[i][0, 2])
               and before.positions_m[i][0, 2] > 4.0)
    tri = before.positions_m[top].astype(np.float64)
    # Rotate 90 degrees about the y axis through the triangle's centroid: z <-> x.
    c = tri.mean(axis=0)
    rotated = np.stack([c[0] + (tri[:, 2] - c[2]), tri[:, 1], c[2] - (tri[:, 0] - c[0])], axis=1)
    after = Scene(before.positions_m.copy(), before.normals, before.albedo, before.emission)
    after.positions_m[top] = rotated
    vols, changed, layers = incremental(gl, before, after)
    assert_volumes_equal(vols, voxelize(gl, after, INCREMENTAL_GRID))
    # An axis-aligned plane at w (not near the grid's edge) reaches layers floor(w) - 1 .. floor(w) + 1:
    # 3 z layers before (z = 5.0), 3 x layers after (x = the centroid's x).
    assert changed == 1
    assert layers == 3 + 3


def test_incremental_random_edits_equal_full_voxelization(gl):
    """3000 random triangles of every size and slope (the slab test's scene); 40 of them moved,
    recoloured, made emissive or collapsed to a point (degenerate: no longer drawn). Exact for the
    reasons above; covers triangles clamped at the grid's faces and ones leaving every slab."""
    rng = np.random.default_rng(2)
    centres = rng.random((3000, 1, 3)) * 10
    tris = (centres + rng.normal(size=(3000, 3, 3)) * rng.random((3000, 1, 1)) * 1.5).astype(np.float32)
    before = Scene(tris, np.zeros_like(tris), rng.random((3000, 3)).astype(np.float32), np.zeros((3000, 3), np.float32))
    grid = Grid.fit(*before.bounds_m(), max_cells=40)
    after = Scene(tris.copy(), before.normals, before.albedo.copy(), before.emission.copy())
    edited = rng.choice(3000, 40, replace=False)
    after.positions_m[edited[:25]] += rng.normal(size=(25, 1, 3)).astype(np.float32)
    after.albedo[edited[25:32]] = 0.5
    after.emission[edited[32:39]] = 3.0
    after.positions_m[edited[39]] = after.positions_m[edited[39], 0]
    v = Voxelizer(gl, grid)
    v.set_scene(before)
    v.run()
    assert v.update(after) == 40
    vols = {k: gl.read(t) for k, t in v.run().items()}
    assert_volumes_equal(vols, voxelize(gl, after, grid))
    assert v.layers_drawn < sum(grid.dims)
