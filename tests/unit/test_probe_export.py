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
    # (the capture's layout) puts it, holds sh.irradiance at that texel's centre direction.
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
                    want = sh.irradiance(coeffs.reshape(g.count, 9, 3)[p, :, 0], dirs[face, j, i])
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
    assert np.abs(back - coeffs).max() < 3e-3 * 2.0


def test_layout_is_json_and_in_world_space():
    g = grid()
    doc = probe_export.layout(g, np.array([10.0, 0.0, -1.0]), "sh", 4, [3],
                              {"sh": "a.exr", "irradiance": "b.exr", "moments": "c.exr", "offsets": "d.exr"})
    again = json.loads(json.dumps(doc))
    assert again["first_probe_m"] == [10.5, -1.0, 1.0]
    assert again["dims"] == [3, 2, 4] and again["probes_off"] == [3]
    assert again["irradiance"]["size"] == list(g.tiled_size(4)) and again["moments"]["size"] == list(g.atlas_size)
    assert again["offsets"] == {**doc["offsets"], "file": "d.exr", "size": [3, 8]} and again["relocated"] is False
