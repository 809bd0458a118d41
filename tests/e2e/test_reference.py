"""The Cycles reference harness: files, shapes, mask, units (analytic spot light), CLI contract.

Scene (built here with bpy): a 2 x 2 m white floor, a 1 m red cube off to one side, a 300 W spot
(bpy.data.lights.new: radius 0, 70 degree cone) 1.9 m above the floor pointing straight down, no
world (no background light), Principled materials with Specular IOR Level 0 (pure Lambert).
"""

from __future__ import annotations

import json
import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from addon.bridge import bench, images

ROOT = Path(__file__).resolve().parents[2]
SPOT = (0.5, -0.5, 1.9)  # clear of the cube (x in -0.95..0.05, y in -0.05..0.95)
WATTS = 300.0
ALBEDO = 0.8

blender = [pytest.mark.slow, pytest.mark.blender]


def build_scene(bpy, path, res_x=320, res_y=240, camera=True):
    """Save the test scene; returns the camera frame (origin, top-left, top-right, bottom-left) in
    world space so a test can cast the ray through any pixel centre without bpy."""
    from mathutils import Vector

    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    scene.world = None

    def material(name, color):
        m = bpy.data.materials.new(name)
        bsdf = m.node_tree.nodes["Principled BSDF"]
        bsdf.inputs["Base Color"].default_value = (*color, 1.0)
        bsdf.inputs["Specular IOR Level"].default_value = 0.0
        return m

    def mesh(name, verts, faces, mat, loc=(0, 0, 0)):
        me = bpy.data.meshes.new(name)
        me.from_pydata(verts, [], faces)
        me.materials.append(mat)
        ob = bpy.data.objects.new(name, me)
        ob.location = loc
        scene.collection.objects.link(ob)

    mesh("Floor", [(-1, -1, 0), (1, -1, 0), (1, 1, 0), (-1, 1, 0)], [(0, 1, 2, 3)],
         material("White", (ALBEDO,) * 3))
    v = [(x, y, z) for x in (-0.5, 0.5) for y in (-0.5, 0.5) for z in (-0.5, 0.5)]
    f = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
    mesh("Cube", v, f, material("Red", (0.8, 0.2, 0.2)), loc=(-0.45, 0.45, 0.5))
    light = bpy.data.lights.new("Spot", type="SPOT")
    light.energy, light.spot_size = WATTS, math.radians(70)
    lo = bpy.data.objects.new("Spot", light)
    lo.location = SPOT  # a light's default orientation points down -Z
    scene.collection.objects.link(lo)
    frame = None
    scene.render.resolution_x, scene.render.resolution_y = res_x, res_y
    if camera:
        cam = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
        cam.location = (0.0, -3.2, 2.4)
        cam.rotation_euler = (Vector((0, 0, 0.3)) - cam.location).to_track_quat("-Z", "Y").to_euler()
        scene.collection.objects.link(cam)
        scene.camera = cam
        bpy.context.view_layer.update()  # matrix_world is stale until the depsgraph runs
        # view_frame: top-right, bottom-right, bottom-left, top-left, in camera space
        tr, _, bl, tl = (np.array(cam.matrix_world @ c) for c in cam.data.view_frame(scene=scene))
        frame = (np.array(cam.matrix_world.translation), tl, tr, bl)
    bpy.ops.wm.save_as_mainfile(filepath=str(path))
    return frame


def floor_point(frame, row, col, h, w):
    """Where the ray through pixel centre (row from the top, col) meets the floor plane z = 0."""
    o, tl, tr, bl = frame
    p = tl + (tr - tl) * (col + 0.5) / w + (bl - tl) * (row + 0.5) / h
    d = p - o
    return o + d * (-o[2] / d[2])


def analytic_direct(x):
    """Diffuse Direct (irradiance / pi) of the bare spot at floor point x, inside the cone core:
    I = P / (4 pi) W/sr, E = I cos(theta) / r^2 with cos(theta) = h / r."""
    r = np.linalg.norm(np.array(SPOT) - x)
    return WATTS / (4 * math.pi) * (SPOT[2] / r) / r**2 / math.pi


@pytest.fixture(scope="module")
def scene_4x3(tmp_path_factory):
    bpy = pytest.importorskip("bpy")
    path = tmp_path_factory.mktemp("scene") / "spot.blend"
    frame = build_scene(bpy, path)
    return path, frame


@pytest.fixture(scope="module")
def ref32(scene_4x3, tmp_path_factory):
    from addon.bridge.reference import render_reference

    out = tmp_path_factory.mktemp("ref32")
    stats = render_reference(scene_4x3[0], out, spp=16, bounces=1, res=32, seed=3)
    return out, stats


def test_exr_roundtrip_is_float_and_top_row_first(tmp_path):
    px = np.zeros((3, 5, 4), dtype=np.float32)
    px[0, :, 0] = 1.0 + 1e-6  # top row; 1e-6 is lost in half floats
    px[..., 3] = 1.0
    images.write_exr(tmp_path / "a.exr", px)
    back = images.read_exr(tmp_path / "a.exr")
    assert back.dtype == np.float32 and back.shape == (3, 5, 4)
    np.testing.assert_array_equal(back, px)
    from addon.engine.errors import SceneError

    with pytest.raises(SceneError, match="no such image"):
        images.read_exr(tmp_path / "missing.exr")
    (tmp_path / "junk.exr").write_bytes(b"not an exr")
    with pytest.raises(SceneError, match="not an OpenEXR file"):
        images.read_multilayer(tmp_path / "junk.exr")


@pytest.mark.slow
@pytest.mark.blender
def test_files_shapes_and_stats(ref32):
    out, stats = ref32
    for name in ("indirect", "direct", "albedo"):
        img = images.read_exr(out / f"{name}.exr")
        assert img.shape == (24, 32, 4), name  # long side 32, aspect 320:240 kept
    saved = json.loads((out / "stats.json").read_text())
    assert saved == stats
    assert stats["spp"] == 16 and stats["bounces"] == 1 and stats["res"] == 32 and stats["seed"] == 3
    assert (stats["width"], stats["height"]) == (32, 24)
    assert stats["render_time_s"] > 0 and stats["blender_version"].startswith("5.")
    assert stats["device"] == "CPU" or ":" in stats["device"]
    c = stats["cycles"]
    assert c["samples"] == 16 and c["diffuse_bounces"] == c["max_bounces"] == 1
    assert c["glossy_bounces"] == c["transmission_bounces"] == 0
    assert c["sample_clamp_indirect"] == 0 and c["sample_clamp_direct"] == 0
    assert c["filter_width"] == pytest.approx(0.01) and c["film_transparent"]
    assert not c["use_adaptive_sampling"] and not c["use_denoising"]


@pytest.mark.slow
@pytest.mark.blender
def test_alpha_mask_and_albedo(ref32, scene_4x3):
    out, _ = ref32
    albedo = images.read_exr(out / "albedo.exr")
    alpha = albedo[..., 3]
    assert alpha[0, 0] == 0.0 and alpha[0, -1] == 0.0  # top corners look over the floor's far edge
    row, col = 18, 22  # the floor right below the spot (checked by the direct-light test)
    assert alpha[row, col] == 1.0
    # 0.01 px filter: alpha is 0 or 1 except where a pixel centre lies exactly on an edge
    assert np.mean((alpha > 0) & (alpha < 1)) < 0.01
    assert 0.2 < alpha.mean() < 0.9
    # Diffuse Color of the white floor is its base colour (Specular IOR Level 0: no specular layer)
    np.testing.assert_allclose(albedo[row, col, :3], ALBEDO, rtol=1e-5)
    # all passes carry the same mask
    for name in ("indirect", "direct"):
        np.testing.assert_array_equal(images.read_exr(out / f"{name}.exr")[..., 3], alpha)
    indirect = images.read_exr(out / "indirect.exr")
    assert np.all(indirect[alpha == 0, :3] == 0) and indirect[alpha == 1, :3].mean() > 0


@pytest.mark.slow
@pytest.mark.blender
def test_direct_light_matches_analytic_spot(ref32, scene_4x3):
    """Diffuse Direct on the floor under the spot = I cos / r^2 / pi, pixel by pixel (5x5 pixels
    around the foot of the spot, all inside the cone core where the blend factor is 1).

    Tolerance 1e-3: a point light on a Lambert floor has no sampling noise in Diffuse Direct (one
    light, no MIS); what remains is the 0.01 px pixel-filter jitter and float32. Measured: the
    largest deviation over these 25 pixels is 3.3e-5 (spp 4 and 16, seeds 0, 1, 3), so 1e-3 is 30x
    the measured spread yet catches any unit error (pi, 4 pi, cos factor) or a flipped image
    (row 0 must be the top: the mirrored pixels see a different distance)."""
    out, _ = ref32
    direct = images.read_exr(out / "direct.exr")
    h, w = direct.shape[:2]
    frame = scene_4x3[1]
    rows, cols = range(16, 21), range(20, 25)
    got = np.array([[direct[r, c, 0] for c in cols] for r in rows])
    want = np.array([[analytic_direct(floor_point(frame, r, c, h, w)) for c in cols] for r in rows])
    # the foot of the spot is inside this window (the test covers the peak)
    foot = [np.linalg.norm(floor_point(frame, r, c, h, w)[:2] - np.array(SPOT[:2])) for r in rows for c in cols]
    assert min(foot) < 0.1
    np.testing.assert_allclose(got, want, rtol=1e-3)
    # the centre of that window is P / (4 pi) / h^2 / pi to within the 0.05 m the pixel is off it
    assert direct[18, 22, 0] == pytest.approx(WATTS / (4 * math.pi) / SPOT[2] ** 2 / math.pi, rel=5e-3)


@pytest.mark.slow
@pytest.mark.blender
def test_aspect_portrait(tmp_path):
    bpy = pytest.importorskip("bpy")
    from addon.bridge.reference import render_reference

    build_scene(bpy, tmp_path / "p.blend", res_x=200, res_y=300)
    stats = render_reference(tmp_path / "p.blend", tmp_path / "out", spp=1, bounces=2, res=40, seed=0)
    assert (stats["width"], stats["height"]) == (27, 40)  # 40 * 200 / 300 = 26.7 -> 27
    assert images.read_exr(tmp_path / "out" / "indirect.exr").shape == (40, 27, 4)
    assert stats["cycles"]["diffuse_bounces"] == 2


@pytest.mark.slow
@pytest.mark.blender
def test_an_image_cycles_cannot_load_is_named_in_the_notes(tmp_path):
    """The floor's Base Color reads an image whose file is gone: Cycles renders it magenta, so the
    reference's stats.json says which image and where it was looked for; a scene without one says
    nothing (the notes are empty)."""
    bpy = pytest.importorskip("bpy")
    from addon.bridge.reference import render_reference

    build_scene(bpy, tmp_path / "ok.blend")
    assert render_reference(tmp_path / "ok.blend", tmp_path / "ok", spp=1, res=16)["notes"] == []
    img = bpy.data.images.new("gone", 4, 4)
    img.source, img.filepath = "FILE", str(tmp_path / "no-such-texture.png")
    mat = bpy.data.objects["Floor"].data.materials[0]
    tex = mat.node_tree.nodes.new("ShaderNodeTexImage")
    tex.image = img
    mat.node_tree.links.new(tex.outputs["Color"], mat.node_tree.nodes["Principled BSDF"].inputs["Base Color"])
    bpy.ops.wm.save_as_mainfile(filepath=str(tmp_path / "gone.blend"))
    stats = render_reference(tmp_path / "gone.blend", tmp_path / "gone", spp=1, res=16)
    assert len(stats["notes"]) == 1 and "'gone'" in stats["notes"][0] and "no-such-texture.png" in stats["notes"][0]
    albedo = images.read_exr(tmp_path / "gone" / "albedo.exr")
    floor = albedo[albedo[..., 3] > 0.5][:, :3]
    assert np.isclose(floor, [1.0, 0.0, 1.0], atol=2e-3).all(axis=1).any()  # magenta, as the note says


@pytest.mark.slow
@pytest.mark.blender
def test_noise_floor_and_curve(scene_4x3, tmp_path):
    from addon.bridge.reference import cycles_curve, noise_floor, render_reference

    nf = noise_floor(scene_4x3[0], spp=16, bounces=1, res=32)
    assert nf["pixels"] > 100 and nf["seeds"] == [0, 1] and len(nf["time_s"]) == 2
    assert 0 < nf["rel_rmse_8"] < nf["rel_rmse"] < 2  # box averaging removes part of the noise
    assert 0.7 < nf["bias"] < 1.3
    render_reference(scene_4x3[0], tmp_path / "ref", spp=256, bounces=1, res=32, seed=0)
    curve = cycles_curve(scene_4x3[0], [16, 4], 1, 32, tmp_path / "ref")
    assert [p["spp"] for p in curve] == [4, 16]
    assert set(curve[0]) == {"spp", "time_s", "rel_rmse", "rel_rmse_8", "bias"}
    # 4x the samples: error ~ 1/2 (plus the 256 spp reference's own noise)
    assert curve[1]["rel_rmse"] < 0.75 * curve[0]["rel_rmse"]


def cli(*args):
    return subprocess.run([sys.executable, "-m", "addon", *map(str, args)], cwd=ROOT,
                          capture_output=True, text=True, timeout=120)


@pytest.mark.slow
@pytest.mark.blender
def test_cli_reference_and_compare(scene_4x3, ref32, tmp_path):
    out = tmp_path / "cli"
    r = cli("reference", scene_4x3[0], "--out", out, "--spp", 4, "--res", 32, "--seed", 5)
    assert r.returncode == 0, r.stderr
    stats = json.loads(r.stdout.strip().splitlines()[-1])
    assert stats["seed"] == stats["cycles"]["seed"] == 5 and (out / "albedo.exr").is_file()  # the seed used
    # compare: the reference (B) has alpha -> masked
    r = cli("compare", out / "indirect.exr", ref32[0] / "indirect.exr")
    assert r.returncode == 0, r.stderr
    got = json.loads(r.stdout)
    assert got["masked"] is True and got["pixels"] == int((images.read_exr(out / "albedo.exr")[..., 3] > 0.5).sum())
    assert got["rel_rmse"] > got["rel_rmse_8"] > 0
    # same file against itself: zero error
    r = cli("compare", ref32[0] / "direct.exr", ref32[0] / "direct.exr")
    same = json.loads(r.stdout)
    assert same["rel_rmse"] == 0.0 and same["hdr_flip"] == 0.0  # FLIP of identical images is exactly 0


def test_cli_compare_rgb_and_size_mismatch(tmp_path):
    images.write_exr(tmp_path / "a.exr", np.full((4, 8, 3), 2.0, np.float32))
    images.write_exr(tmp_path / "b.exr", np.full((4, 8, 3), 1.0, np.float32))
    images.write_exr(tmp_path / "c.exr", np.full((8, 8, 3), 1.0, np.float32))
    r = cli("compare", tmp_path / "a.exr", tmp_path / "b.exr")
    got = json.loads(r.stdout)
    assert got.pop("hdr_flip") > 0  # 2 vs 1 everywhere: a visible difference (value is FLIP's business)
    assert got == {"rel_rmse": 1.0, "rel_rmse_8": 1.0, "bias": 2.0, "pixels": 32, "note": None, "masked": False}
    r = cli("compare", tmp_path / "a.exr", tmp_path / "c.exr")
    assert r.returncode == 2 and "differ in size" in r.stderr
    assert len(r.stderr.strip().splitlines()) == 1 and "Traceback" not in r.stderr
    r = cli("compare", tmp_path / "a.exr", tmp_path / "nope.exr")
    assert r.returncode == 2 and len(r.stderr.strip().splitlines()) == 1


def test_cli_compare_leaves_out_pixels_black_in_either_albedo_as_bench_does(tmp_path):
    # A reference folder as `reference` writes it: the light with alpha, and albedo.exr beside it. The
    # pixel whose albedo is black (an emitter's panel: Cycles' Diffuse passes are 0 there) is left
    # out, as the benchmark leaves it out: ours reads 1 everywhere, the reference 1 except 0 there.
    ref = tmp_path / "ref"
    ref.mkdir()
    light = np.ones((4, 8, 4), np.float32)
    light[0, 0, :3] = 0.0
    albedo = np.full((4, 8, 4), 0.5, np.float32)
    albedo[0, 0, :3] = 0.0
    images.write_exr(ref / "direct.exr", light)
    images.write_exr(ref / "albedo.exr", albedo)
    images.write_exr(tmp_path / "ours.exr", np.ones((4, 8, 3), np.float32))
    got = json.loads(cli("compare", tmp_path / "ours.exr", ref / "direct.exr").stdout)
    assert (got["pixels"], got["rel_rmse"], got["bias"], got["masked"]) == (31, 0.0, 1.0, True)
    (ref / "albedo.exr").unlink()  # without it every covered pixel counts: 1 of 32 off by the mean
    got = json.loads(cli("compare", tmp_path / "ours.exr", ref / "direct.exr").stdout)
    assert got["pixels"] == 32 and got["rel_rmse"] == pytest.approx(np.sqrt(1 / 32) / (31 / 32), rel=1e-6)
    # The same pixel black in our albedo.exr alone (Cycles saw the ceiling behind a panel's silhouette
    # in one stray sample): left out again, and bench's own comparison agrees.
    images.write_exr(tmp_path / "albedo.exr", albedo)
    got = json.loads(cli("compare", tmp_path / "ours.exr", ref / "direct.exr").stdout)
    assert (got["pixels"], got["rel_rmse"], got["bias"]) == (31, 0.0, 1.0)
    assert bench._compare(tmp_path / "ours.exr", ref / "direct.exr")["pixels"] == 31


@pytest.mark.slow
@pytest.mark.blender
@pytest.mark.parametrize("extra, message", [
    (("--spp", 0), "--spp"),
    (("--bounces", 9), "--bounces"),
    (("--bounces", 0), "--bounces"),
    (("--res", 4), "--res"),
    (("--res", 9000), "--res"),
    (("--seed", -1), "--seed -1"),  # Cycles would clamp it to 0 and the stats would name -1
])
def test_cli_reference_bad_values(scene_4x3, tmp_path, extra, message):
    r = cli("reference", scene_4x3[0], "--out", tmp_path / "o", *extra)
    assert r.returncode == 2 and message in r.stderr
    assert len(r.stderr.strip().splitlines()) == 1 and "Traceback" not in r.stderr


@pytest.mark.slow
@pytest.mark.blender
def test_cli_reference_missing_file_and_no_camera(tmp_path):
    bpy = pytest.importorskip("bpy")
    r = cli("reference", tmp_path / "missing.blend", "--out", tmp_path / "o")
    assert r.returncode == 2 and "no such file" in r.stderr and len(r.stderr.strip().splitlines()) == 1
    build_scene(bpy, tmp_path / "nocam.blend", camera=False)
    r = cli("reference", tmp_path / "nocam.blend", "--out", tmp_path / "o", "--res", 16, "--spp", 1)
    assert r.returncode == 2 and "no camera" in r.stderr
    # bpy prints its own log lines to stderr; the error is the last line and there is no traceback
    assert r.stderr.strip().splitlines()[-1].startswith("error:") and "Traceback" not in r.stderr
