"""Batch bakes: several .blend files in one run, and the LPV volume and probe grid exports with their
documented layouts."""

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

pytestmark = [pytest.mark.blender, pytest.mark.slow]
ROOT = Path(__file__).resolve().parents[2]


def cli(*args):
    return subprocess.run([sys.executable, "-m", "addon", *map(str, args)], cwd=ROOT, capture_output=True, text=True)


@pytest.fixture(scope="module")
def blends(tmp_path_factory):
    d = tmp_path_factory.mktemp("blends")
    for name in ("cornell", "cornell-point"):
        assert cli("scene", name, "--out", d / f"{name}.blend").returncode == 0
    return d


def test_several_files_in_one_run(blends, tmp_path):
    out = tmp_path / "out"
    r = cli("bake", blends / "cornell.blend", blends / "cornell-point.blend", "--out", out, "--size", 16,
            "--objects", "Floor,LeftWall", "--visibility", "none", "--quiet")
    assert r.returncode == 0, r.stderr
    lines = [line for line in r.stdout.splitlines() if line.startswith("ok")]
    assert len(lines) == 4  # one line per object, two objects in each of two files
    index = json.loads((out / "bake.json").read_text())
    assert len(index["files"]) == 2
    for stem in ("cornell", "cornell-point"):
        summary = json.loads((out / stem / "bake.json").read_text())
        assert set(summary["objects"]) == {"Floor", "LeftWall"}
        assert (out / stem / "Floor_indirect.exr").is_file()
    r = cli("bake", blends / "cornell.blend", blends / "cornell-point.blend", "--out", out, "--save-blend",
            tmp_path / "x.blend")
    assert r.returncode == 2 and "one input file" in r.stderr


def test_volume_follows_its_documented_layout(blends, tmp_path):
    # The .npz must let an engine reproduce Bounce's own LPV lighting: evaluate the documented lookup
    # (trilinear SH at p + 0.5 cell n, E = max(0, c . lobe(-n)) / cell^2, Diffuse Indirect = E / pi) at
    # the G-buffer points of a render of the same scene and configuration, and compare with the render.
    # Tolerance 2 % of the image's mean: GPU trilinear filtering uses 8-bit fractional weights.
    import bpy

    from addon.bridge.capture import SceneCache
    from addon.bridge.pipeline import backend, open_blend
    from addon.engine import sh
    from addon.engine.config import GIConfig, LpvConfig, RsmConfig
    from addon.engine.methods.lpv import LpvMethod

    out = tmp_path / "vol"
    r = cli("bake", blends / "cornell.blend", "--out", out, "--target", "volume", "--method", "lpv",
            "--grid", 16, "--variant", "improved")
    assert r.returncode == 0, r.stderr
    vol = np.load(out / "cornell_lpv_sh.npz")
    dims = vol["dims"]
    assert vol["sh_r"].shape == (dims[2], dims[1], dims[0], 4)

    open_blend(blends / "cornell.blend")
    scene = SceneCache().update(bpy.context.evaluated_depsgraph_get(), 48, 48)
    method = LpvMethod(backend(), GIConfig(method="lpv"), RsmConfig(visibility="voxel"),
                       LpvConfig(grid_cells=16, variant="improved", geometry_volume=True))
    method.set_scene(scene)
    images = method.run().images
    be = backend()
    pos = be.read(method.gbuf["position"])[::-1]  # local (re-centred) frame, row 0 = top
    nrm = be.read(method.gbuf["normal"])[::-1, :, :3]
    covered = pos[..., 3] > 0
    p_world = pos[..., :3][covered] + method.origin_m
    n = nrm[covered]
    h = float(vol["cell_size_m"])
    g = (p_world + 0.5 * h * n - vol["origin_m"]) / h - 0.5  # continuous index of cell centres
    g = np.clip(g, 0, dims - 1)
    i0 = np.floor(g).astype(int)
    f = g - i0
    i1 = np.minimum(i0 + 1, dims - 1)
    lobe = sh.cosine_lobe_l1(-n)
    vox = vol["vox_normal"]  # written because the geometry volume is on: the weighted lookup
    sums = np.zeros((len(g), 3))
    plain = np.zeros((len(g), 3))
    weights = np.zeros(len(g))
    for dx in (0, 1):
        for dy in (0, 1):
            for dz in (0, 1):
                ix = np.where(dx, i1[:, 0], i0[:, 0])
                iy = np.where(dy, i1[:, 1], i0[:, 1])
                iz = np.where(dz, i1[:, 2], i0[:, 2])
                w = (np.where(dx, f[:, 0], 1 - f[:, 0]) * np.where(dy, f[:, 1], 1 - f[:, 1])
                     * np.where(dz, f[:, 2], 1 - f[:, 2]))
                cell = vox[iz, iy, ix]
                through = 1.0 - np.minimum(1.0, cell[:, 3] * np.abs((cell[:, :3] * n).sum(axis=1)))
                v = np.stack([(vol[key][iz, iy, ix] * lobe).sum(axis=1) for key in ("sh_r", "sh_g", "sh_b")], 1)
                plain += w[:, None] * v
                sums += (w * through)[:, None] * v
                weights += w * through
    blocked = weights <= 1e-4
    value = np.where(blocked[:, None], plain, sums / np.where(blocked, 1.0, weights)[:, None])
    expected = np.maximum(value, 0) / h**2 / np.pi
    got = images["indirect"][..., :3][covered]
    assert got.mean() > 0
    assert np.abs(got - expected).mean() <= 0.02 * got.mean()


@pytest.mark.parametrize("encoding", ["sh", "irradiance"])
def test_probes_follow_their_documented_layout(blends, tmp_path, encoding):
    # An engine reading the exported atlases at a probe must get what Bounce's own lookup gives there:
    # the lookup (probe_lookup.run) is run at points whose biased test point is exactly a probe, with the
    # irradiance atlas's texel normals, so its trilinear weights select that probe alone and it returns
    # E(n) / pi. Compared with the exported irradiance texel found through the JSON's layout (tile, face,
    # rows) and world position (first_probe_m). Tolerance 1e-4 of the mean: float32 positions put
    # weights of ~1e-6 on the neighbouring probes. With the SH encoding the SH file must give the same E
    # by the documented formula; with the irradiance encoding the SH file is a fit (checked for its mean).
    # The octahedral irradiance atlas likewise, at its interior texels' directions.
    import bpy

    from addon.bridge.capture import SceneCache
    from addon.bridge.images import read_exr
    from addon.bridge.pipeline import backend, open_blend
    from addon.engine import sh
    from addon.engine.config import GIConfig, ProbesConfig, RsmConfig
    from addon.engine.methods.probes import ProbesMethod
    from addon.engine.passes import probe_lookup
    from addon.engine.probe_grid import texel_directions

    out = tmp_path / "probes"
    r = cli("bake", blends / "cornell.blend", "--out", out, "--target", "probes", "--probes-per-side", 4,
            "--encoding", encoding, "--quiet")
    assert r.returncode == 0, r.stderr
    doc = json.loads((out / "cornell_probes.json").read_text())
    keys = ("sh", "irradiance", "moments", "offsets")
    atlas = {k: read_exr(out / doc[k]["file"])[::-1] for k in keys}  # row 0 = bottom
    octahedral = {k: read_exr(out / doc["octahedral"][k]["file"])[::-1] for k in ("irradiance", "moments")}
    for k in octahedral:
        assert list(octahedral[k].shape[1::-1]) == doc["octahedral"][k]["size"] and octahedral[k].min() >= 0
    for k in atlas:
        assert list(atlas[k].shape[1::-1]) == doc[k]["size"] and np.isfinite(atlas[k]).all()
    assert atlas["irradiance"].min() >= 0 and atlas["moments"].min() >= 0
    assert not doc["relocated"] and np.all(atlas["offsets"][..., :3] == 0)  # relocation is off

    open_blend(blends / "cornell.blend")
    scene = SceneCache().update(bpy.context.evaluated_depsgraph_get(), 8, 8)
    config = ProbesConfig(probes_per_side=4, encoding=encoding)
    be = backend()
    method = ProbesMethod(be, GIConfig(method="probes"), RsmConfig(), config)
    method.set_scene(scene)
    method.solve_light_field()
    grid = method.grid
    assert doc["dims"] == list(grid.dims) and doc["spacing_m"] == pytest.approx(grid.spacing_m)

    n_tex = doc["irradiance"]["face_texels"]
    cube_normals = texel_directions(n_tex).reshape(-1, 3)                   # face, row j, column i
    # The octahedral tiles' interior texel directions, by the layout's own formula (row j, column i).
    k_oct = doc["octahedral"]["irradiance"]["texels"]
    c = 2.0 * (np.arange(k_oct) + 0.5) / k_oct - 1.0
    v, u = (a.ravel() for a in np.meshgrid(c, c, indexing="ij"))
    z = 1.0 - np.abs(u) - np.abs(v)
    sign_u, sign_v = np.where(u >= 0, 1.0, -1.0), np.where(v >= 0, 1.0, -1.0)
    oct_normals = np.where((z < 0)[:, None], np.stack([(1 - np.abs(v)) * sign_u, (1 - np.abs(u)) * sign_v, z], 1),
                           np.stack([u, v, z], 1))
    oct_normals /= np.linalg.norm(oct_normals, axis=1, keepdims=True)
    normals = np.concatenate([cube_normals, oct_normals])
    nx, ny, nz = doc["dims"]
    probes = [(ix, iy, iz) for iz in range(nz) for iy in range(ny) for ix in range(nx)]
    world = np.array(doc["first_probe_m"]) + np.array(probes) * doc["spacing_m"]
    local = world - method.origin_m
    bias_m = config.normal_bias * grid.spacing_m
    pos = np.zeros((len(probes), len(normals), 4), np.float32)
    pos[..., :3] = local[:, None] - bias_m * normals[None]
    pos[..., 3] = 1.0
    nrm = np.zeros_like(pos)
    nrm[..., :3] = normals[None]
    size = (len(normals), len(probes))
    indirect = be.texture(size)
    probe_lookup.run(be, be.texture(size, data=pos), be.texture(size, data=nrm), method.field(), indirect, grid,
                     config)
    looked_up = be.read(indirect)[..., :3] * np.pi                           # (probe, normal, rgb): E
    looked_up_oct = looked_up[:, len(cube_normals):]
    looked_up = looked_up[:, :len(cube_normals)]
    normals = cube_normals

    cols = doc["tiles_per_row"]
    exported = np.zeros_like(looked_up)
    exported_oct = np.zeros_like(looked_up_oct)
    from_sh = np.zeros_like(looked_up)
    lobe = sh.windowed_cosine_lobe_l2(normals)
    for row, (ix, iy, iz) in enumerate(probes):
        p = ix + nx * (iy + ny * iz)
        tile = np.array([3 * n_tex * (p % cols), 2 * n_tex * (p // cols)])
        for k, _ in enumerate(normals):
            face, j, i = np.unravel_index(k, (6, n_tex, n_tex))
            x, y = tile + [n_tex * (face % 3) + i, n_tex * (face // 3) + j]
            exported[row, k] = atlas["irradiance"][y, x, :3]
        tile = octahedral["irradiance"][(k_oct + 2) * (iy + ny * iz):(k_oct + 2) * (iy + ny * iz + 1),
                                        (k_oct + 2) * ix:(k_oct + 2) * (ix + 1), :3]
        exported_oct[row] = tile[1:-1, 1:-1].reshape(-1, 3)
        coeffs = np.stack([atlas["sh"][iy + ny * iz, c * nx + ix, :3] for c in range(9)])  # (9, rgb)
        from_sh[row] = np.maximum(lobe @ coeffs, 0.0)
    off = set(doc["probes_off"])
    on = np.array([ix + nx * (iy + ny * iz) not in off for ix, iy, iz in probes])
    assert looked_up[on].mean() > 0
    assert np.abs(exported[on] - looked_up[on]).max() <= 1e-4 * looked_up[on].mean()
    # DDGI's octahedral irradiance: what the lookup gives at each interior texel's direction.
    assert np.abs(exported_oct[on] - looked_up_oct[on]).max() <= 1e-4 * looked_up_oct[on].mean()
    if encoding == "sh":
        assert np.abs(from_sh[on] - looked_up[on]).max() <= 1e-4 * looked_up[on].mean()
    else:
        # The fit's constant band is exact (the mean of E over the sphere is pi times the mean radiance).
        assert from_sh[on].mean() == pytest.approx(exported[on].mean(), rel=0.02)  # measured 1.004
