"""The probe volume's arrays and layout (engine/probe_export.py), exact cases in numpy."""

import json

import numpy as np

from addon.engine import probe_export, sh
from addon.engine.probe_grid import ProbeGrid, texel_directions


def grid(dims=(3, 2, 4), face_texels=4) -> ProbeGrid:
    return ProbeGrid(np.array([0.5, -1.0, 2.0]), 0.25, dims, face_texels)


def test_sh_table_indexing_and_inverse():
    g = grid()
    nx, ny, nz = g.dims
    w, h = g.sh_size
    table = np.zeros((h, w, 4))
    for iz in range(nz):
        for iy in range(ny):
            for ix in range(nx):
                for c in range(9):
                    table[iy + ny * iz, c * nx + ix, :3] = [c, ix + 10 * iy + 100 * iz, -1.0]
    coeffs = probe_export.sh_grid(g, table)
    assert coeffs.shape == (nz, ny, nx, 9, 3)
    assert coeffs[3, 1, 2, 7].tolist() == [7.0, 2 + 10 + 300, -1.0]
    assert np.array_equal(probe_export.sh_table(g, coeffs), table[..., :3])


def test_constant_radiance_gives_pi_l_everywhere():
    # A uniform field of radiance L projects to c_0 = L * 4 pi Y_00 and nothing else; its irradiance is
    # exactly pi L at every normal. Tolerance: float64 rounding.
    g = grid()
    radiance = np.array([0.3, 1.0, 2.5])
    coeffs = np.zeros((*g.dims[::-1], 9, 3))
    coeffs[..., 0, :] = radiance * 4.0 * np.pi * sh.Y00
    atlas = probe_export.irradiance_from_sh(g, coeffs, 4)
    w, h = g.tiled_size(4)
    assert atlas.shape == (h, w, 3)
    rows, cols = probe_export._face_texels(g, 4)
    written = np.zeros((h, w), bool)
    written[rows, cols] = True
    assert written.sum() == g.count * 6 * 16  # every texel of every face, no two on one texel
    np.testing.assert_allclose(atlas[written], np.broadcast_to(np.pi * radiance, (written.sum(), 3)), rtol=1e-12)
    assert not atlas[~written].any()


def test_irradiance_atlas_places_each_face_where_the_grid_says():
    # A field brighter towards +x than -x: every texel of every face, found where ProbeGrid.face_origin
    # (the capture's layout) puts it, holds the lookup's (windowed) irradiance at that texel's centre
    # direction.
    g = grid(face_texels=2)
    coeffs = np.zeros((*g.dims[::-1], 9, 3))
    coeffs[..., 0, :] = 1.0
    coeffs[..., 3, :] = 0.5  # Y_1 x term
    atlas = probe_export.irradiance_from_sh(g, coeffs, 2)
    dirs = texel_directions(2)
    for p in (0, 5, g.count - 1):
        for face in range(6):
            x0, y0 = g.face_origin(p, face)  # this grid's tiles for n = 2 are the capture's own layout
            for j in range(2):
                for i in range(2):
                    lobe = sh.windowed_cosine_lobe_l2(dirs[face, j, i])
                    want = max(0.0, lobe @ coeffs.reshape(g.count, 9, 3)[p, :, 0])
                    assert abs(atlas[y0 + j, x0 + i, 0] - want) < 1e-12


def test_irradiance_round_trips_to_sh():
    # A band-limited field (bands 0..2) whose irradiance is positive everywhere, so the clamp never acts:
    # projecting its irradiance cube map back recovers the coefficients up to the texel-centre
    # quadrature, whose error falls as 1 / n^2 (largest error / c_0 measured: n = 4 2.1e-3, 8 4.6e-4,
    # 16 1.1e-4). At the exported n = 4 the bound is 3e-3 of c_0.
    g = grid(dims=(2, 1, 1))
    rng = np.random.default_rng(1)
    coeffs = np.zeros((*g.dims[::-1], 9, 3))
    coeffs[..., 0, :] = 2.0
    coeffs[..., 1:, :] = rng.uniform(-0.15, 0.15, coeffs[..., 1:, :].shape)
    atlas = probe_export.irradiance_from_sh(g, coeffs, 4)
    assert atlas[atlas.any(axis=-1)].min() > 0  # the clamp did not act
    back = probe_export.sh_from_irradiance(g, atlas, 4)
    # The atlas is the lookup's irradiance, each band l windowed by h_l (sh.IRRADIANCE_WINDOW_L2), which
    # the projection (divided by A_l only, the irradiance encoding's exact maps) keeps.
    window = np.array([sh.IRRADIANCE_WINDOW_L2[sh.band_of(i)] for i in range(9)])[:, None]
    assert np.abs(back - coeffs * window).max() < 3e-3 * 2.0


def test_layout_is_json_and_in_world_space():
    g = grid()
    doc = probe_export.layout(g, np.array([10.0, 0.0, -1.0]), "sh", 4, [3],
                              {k: f"{k}.exr" for k in probe_export.FILES})
    again = json.loads(json.dumps(doc))
    assert again["first_probe_m"] == [10.5, -1.0, 1.0]
    assert again["dims"] == [3, 2, 4] and again["probes_off"] == [3]
    assert again["irradiance"]["size"] == list(g.tiled_size(4)) and again["moments"]["size"] == list(g.atlas_size)
    assert again["offsets"] == {**doc["offsets"], "file": "offsets.exr", "size": [3, 8]} and again["relocated"] is False
    oct_doc = again["octahedral"]
    assert oct_doc["irradiance"]["size"] == [8 * 3, 8 * 2 * 4] and oct_doc["moments"]["size"] == [16 * 3, 16 * 2 * 4]


def test_octahedral_map_round_trips_and_covers_the_sphere():
    # Directions on every octant (and the poles and the horizon, where the two halves meet) come back
    # from their octahedral coordinates to float64 rounding; a tile's texel centres are unit directions
    # on both halves, the centre texels beside +z and the corner texels beside -z.
    rng = np.random.default_rng(3)
    d = rng.normal(size=(4000, 3))
    d = np.concatenate([d, np.eye(3), -np.eye(3), [[1.0, 1.0, 0.0], [-1.0, 0.5, 0.0]]])
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    uv = probe_export.octahedral_encode(d)
    assert np.abs(uv).max() <= 1.0 + 1e-12
    assert np.abs(probe_export.octahedral_decode(uv) - d).max() < 1e-12
    k = 6
    dirs = probe_export.octahedral_directions(k)
    assert np.allclose(np.linalg.norm(dirs, axis=-1), 1.0)
    # As many texels on the lower half as on the upper; k = 6 puts the 12 centres with |u| + |v| = 1
    # (u, v in +-1/6, +-3/6, +-5/6) on the horizon, z = 0.
    assert (dirs[..., 2] > 1e-9).sum() == (dirs[..., 2] < -1e-9).sum() == 12
    assert dirs[k // 2, k // 2, 2] > 0.9 and dirs[0, 0, 2] < -0.9


def test_octahedral_border_repeats_the_texel_the_octahedron_folds_onto():
    # A border texel's centre lies half a texel past an edge of the square. Folding uv back across
    # the edge it crossed (u > 1: (2 - u, -v); u < -1: (-2 - u, -v); likewise for v with u negated),
    # as the octahedron's edges are glued, lands on an interior texel's centre: the border must repeat
    # that texel's value, so that bilinear filtering across the edge reads the sphere's neighbours.
    # And the fold is a direction's identity: the border texel's extended decode meets the folded one.
    k = 5
    tiles = np.arange(k * k * 2, dtype=np.float64).reshape(k, k, 2)
    out = probe_export.octahedral_border(tiles)
    assert out.shape == (k + 2, k + 2, 2) and np.array_equal(out[1:-1, 1:-1], tiles)
    for y in range(k + 2):
        for x in range(k + 2):
            u, v = 2.0 * (x - 1 + 0.5) / k - 1.0, 2.0 * (y - 1 + 0.5) / k - 1.0
            while abs(u) > 1.0 or abs(v) > 1.0:
                if abs(u) > 1.0:
                    u, v = np.sign(u) * 2.0 - u, -v
                else:
                    u, v = -u, np.sign(v) * 2.0 - v
            i, j = round((u + 1.0) * k / 2.0 - 0.5), round((v + 1.0) * k / 2.0 - 0.5)
            assert np.array_equal(out[y, x], tiles[j, i]), (x, y)


def test_octahedral_irradiance_is_the_lookup_at_each_texel_direction():
    # From SH: every interior texel holds E = max(0, sum_i A_l c_i Y_i(d)) at its direction (float64
    # rounding). From an irradiance cube atlas holding a field linear in the normal, E(n) = a + b . n
    # at its texel centres: the octahedral texels read it bilinearly within a face, clamped at the
    # face's edges, as the renderer does, so each is a weighted mean of a + b . c over texel centres c
    # less than a texel diagonal (2 sqrt 2 / n in face coordinates, no more as an angle) from its
    # direction d: within |b| 2 sqrt 2 / n of a + b . d. A constant atlas gives a constant tile (to rounding);
    # the exact reading is held end to end against the renderer's lookup (tests/blender/test_bake_batch).
    g = grid(dims=(2, 1, 3))
    k = probe_export.OCT_IRRADIANCE_TEXELS
    rng = np.random.default_rng(5)
    coeffs = rng.normal(size=(*g.dims[::-1], 9, 3))
    coeffs[..., 0, :] += 5.0
    atlas = probe_export.octahedral_irradiance(g, coeffs, None, 4)
    w, h = probe_export.octahedral_size(g, k)
    assert atlas.shape == (h, w, 3)
    dirs = probe_export.octahedral_directions(k).reshape(-1, 3)
    nx, ny, _ = g.dims
    for iz, iy, ix in [(0, 0, 0), (2, 0, 1)]:
        tile = atlas[(k + 2) * (iy + ny * iz):(k + 2) * (iy + ny * iz + 1), (k + 2) * ix:(k + 2) * (ix + 1)]
        expected = np.maximum(sh.windowed_cosine_lobe_l2(dirs) @ coeffs[iz, iy, ix], 0.0)
        assert np.allclose(tile[1:-1, 1:-1].reshape(-1, 3), expected, atol=1e-12)
    a, b = np.array([2.0, 1.0, 3.0]), np.array([0.5, -0.3, 0.2])
    n = 4
    cube = np.zeros((*g.tiled_size(n)[::-1], 3))
    rows, cols = probe_export._face_texels(g, n)
    cube[rows, cols] = a + (texel_directions(n) @ b)[None, ..., None]
    oct_atlas = probe_export.octahedral_irradiance(g, None, cube, n)
    tile = oct_atlas[:k + 2, :k + 2][1:-1, 1:-1].reshape(-1, 3)
    err = np.abs(tile - (a + (dirs @ b)[:, None]))
    assert 0 < err.max() <= np.linalg.norm(b) * 2 * np.sqrt(2) / n
    flat = probe_export.octahedral_irradiance(g, None, np.full_like(cube, 1.5), n)
    assert np.allclose(flat, 1.5, rtol=1e-15, atol=0)  # bilinear weights summing to 1 in float64


def test_octahedral_moments_keep_both_moments_and_a_zero_third_channel():
    # Moments constant over the capture (mean 2 m, mean square 5 m^2) read back constant in every
    # texel of every tile, border included, at DDGI's moment tile size; the third channel is 0.
    g = grid(dims=(2, 2, 1), face_texels=4)
    w, h = g.atlas_size
    moments = np.zeros((h, w, 4))
    moments[..., 0], moments[..., 1], moments[..., 2] = 2.0, 5.0, 7.0
    got = probe_export.octahedral_moments(g, moments)
    k = probe_export.OCT_MOMENT_TEXELS
    assert got.shape == (2 * (k + 2), 2 * (k + 2), 3) == (*probe_export.octahedral_size(g, k)[::-1], 3)
    assert np.allclose(got[..., 0], 2.0, rtol=1e-15) and np.allclose(got[..., 1], 5.0, rtol=1e-15)
    assert np.all(got[..., 2] == 0.0)
