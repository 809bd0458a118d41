"""`python -m addon bake`: outputs, bake.json, per-object problems, path sanitising, shards, exit codes."""

import hashlib
import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

pytestmark = pytest.mark.blender
ROOT = Path(__file__).resolve().parents[2]
FAST = ["--size", "16", "--rsm-res", "32", "--vpl-samples", "4", "--visibility", "none", "--quiet"]

# Cornell box plus objects that must each fail or warn on their own.
BUILD = """
import bpy, sys
sys.path.insert(0, {root!r})
from addon.bridge import scenes
scenes.build("cornell")
def mesh(name, verts, faces, uvs=None):
    me = bpy.data.meshes.new(name)
    me.from_pydata(verts, [], faces)
    if uvs is not None:
        me.uv_layers.new(name="UVMap").data.foreach_set("uv", [c for uv in uvs for c in uv])
    ob = bpy.data.objects.new(name, me)
    bpy.context.scene.collection.objects.link(ob)
quad = [(0, 0, 1), (0.2, 0, 1), (0.2, 0.2, 1), (0, 0.2, 1)]
mesh("NoUV", quad, [(0, 1, 2, 3)])
mesh("../evil/Esc", quad, [(0, 1, 2, 3)], [(0, 0), (1, 0), (1, 1), (0, 1)])
two = quad + [(0.3, 0, 1), (0.5, 0, 1), (0.5, 0.2, 1), (0.3, 0.2, 1)]
mesh("Overlap", two, [(0, 1, 2, 3), (4, 5, 6, 7)], [(0, 0), (1, 0), (1, 1), (0, 1)] * 2)
mesh("ZeroUV", two, [(0, 1, 2, 3), (4, 5, 6, 7)], [(0, 0), (1, 0), (1, 1), (0, 1)] + [(0.5, 0.5)] * 4)
bpy.ops.wm.save_as_mainfile(filepath={out!r})
"""


def cli(*args):
    return subprocess.run([sys.executable, "-m", "addon", *args], cwd=ROOT, capture_output=True, text=True)


@pytest.fixture(scope="module")
def blend(tmp_path_factory):
    path = tmp_path_factory.mktemp("bake") / "bad.blend"
    subprocess.run([sys.executable, "-c", BUILD.format(root=str(ROOT), out=str(path))], check=True,
                   capture_output=True)
    return path


def digest(path):
    return hashlib.sha256(Path(path).read_bytes()).hexdigest()


def test_bake_reports_each_object_and_keeps_files_inside(blend, tmp_path):
    before = digest(blend)
    out = tmp_path / "out"
    r = cli("bake", str(blend), "--out", str(out), *FAST)
    assert r.returncode == 2, r.stderr  # some objects failed: exit 2 with one line, the others baked
    assert len(r.stderr.strip().splitlines()) == 1 and "NoUV" in r.stderr
    summary = json.loads((out / "bake.json").read_text())
    objs = summary["objects"]
    assert objs["NoUV"]["status"] == "error" and "UV" in objs["NoUV"]["message"]
    assert objs["Overlap"]["status"] == "warning" and "overlapping" in objs["Overlap"]["message"]
    assert objs["ZeroUV"]["status"] == "warning" and "zero UV area" in objs["ZeroUV"]["message"]
    assert objs["Floor"]["status"] == "ok" and objs["Floor"]["size"] == [16, 16]
    # The name with '..' and '/' lands inside DIR, sanitised.
    esc = Path(objs["../evil/Esc"]["file"])
    assert esc.parent == out.resolve() and esc.name == "evil_Esc_indirect.exr" and esc.is_file()
    assert not (tmp_path / "evil").exists()
    assert all(p.parent == out for p in out.rglob("*"))
    # One line of result per object on stdout.
    assert sum(line.split()[1] in objs for line in r.stdout.splitlines() if line.strip()) == len(objs)
    from addon.bridge import images

    floor = images.read_exr(out / "Floor_indirect.exr")
    assert floor.shape == (16, 16, 4) and np.all(floor[..., 3] == 1.0) and floor[..., :3].mean() > 0
    assert digest(blend) == before  # the .blend is never modified
    # Again without --overwrite: every file is skipped with a message.
    r2 = cli("bake", str(blend), "--out", str(out), "--objects", "Floor", *FAST)
    assert r2.returncode == 0
    floor2 = json.loads((out / "bake.json").read_text())["objects"]["Floor"]
    assert floor2["status"] == "skipped" and "--overwrite" in floor2["message"]
    assert "nothing baked" in json.loads((out / "bake.json").read_text())["warnings"][0]


def test_shard_and_vertex_colors_into_a_copy(blend, tmp_path):
    copy = tmp_path / "copy.blend"
    r = cli("bake", str(blend), "--out", str(tmp_path), "--shard", "1/3", "--target", "vertex-colors",
            "--save-blend", str(copy), "--pass", "combined", *FAST)
    names = sorted(["BackWall", "Ceiling", "Floor", "LeftWall", "RightWall", "ShortBox", "TallBox", "NoUV",
                    "../evil/Esc", "Overlap", "ZeroUV"])
    objs = json.loads((tmp_path / "bake.json").read_text())["objects"]
    assert sorted(objs) == names[1::3], r.stderr
    assert r.returncode == 0, r.stderr  # vertex colours need no UVs
    code = (f"import bpy; bpy.ops.wm.open_mainfile(filepath={str(copy)!r}); "
            "print(sorted(o.name for o in bpy.data.objects if o.type == 'MESH' "
            "and 'bounce_combined' in o.data.color_attributes))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert str(sorted(names[1::3])) in out


@pytest.mark.parametrize("args, words", [
    (["missing.blend", "--out", "{tmp}"], "no such file"),
    (["{blend}", "--out", "/proc/bounce_out"], "output directory"),
    (["{blend}", "--out", "/proc"], "not writable"),
    (["{blend}", "--out", "{tmp}", "--shard", "3/3"], "--shard"),
    (["{blend}", "--out", "{tmp}", "--pass", "glossy"], "--pass"),
    (["{blend}", "--out", "{tmp}", "--target", "png"], "--target"),
    (["{blend}", "--out", "{tmp}", "--objects", "Nope"], "Nope"),
    (["{blend}", "--out", "{tmp}", "--supersample", "9"], "--supersample"),
    (["{blend}", "--out", "{tmp}", "--supersample", "0"], "--supersample"),
    (["{blend}", "--out", "{tmp}", "--target", "vertex-colors", "--save-blend", "{tmp}/c.blend", "--self-check"],
     "--self-check"),
])
def test_bad_input_exits_2_with_one_line(blend, tmp_path, args, words):
    r = cli("bake", *[a.format(tmp=tmp_path, blend=blend) for a in args], *FAST)
    assert r.returncode == 2
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error:") and words in lines[0], r.stderr


DARK = """
import bpy, sys
sys.path.insert(0, {root!r})
from addon.bridge import scenes
scenes.build("cornell")
for light in [o for o in bpy.data.objects if o.type == "LIGHT"]:
    bpy.data.objects.remove(light)
bpy.ops.wm.save_as_mainfile(filepath={out!r})
"""


def test_a_scene_without_light_is_baked_with_a_warning(tmp_path):
    # Valid but black: exit 0, and bake.json and stderr say why every value is zero.
    dark = tmp_path / "dark.blend"
    subprocess.run([sys.executable, "-c", DARK.format(root=str(ROOT), out=str(dark))], check=True,
                   capture_output=True)
    out = tmp_path / "out"
    r = cli("bake", str(dark), "--out", str(out), "--objects", "Floor", *FAST)
    assert r.returncode == 0, r.stderr
    summary = json.loads((out / "bake.json").read_text())
    assert len(summary["warnings"]) == 1 and "no light sources" in summary["warnings"][0]
    floor = summary["objects"]["Floor"]
    assert floor["status"] == "warning" and floor["warnings"] == ["no light: every baked value is zero"]
    assert any(line.startswith("warning:") and "no light sources" in line for line in r.stderr.splitlines())


def test_a_lit_bake_has_no_warnings(blend, tmp_path):
    r = cli("bake", str(blend), "--out", str(tmp_path), "--objects", "Floor", *FAST)
    assert r.returncode == 0, r.stderr
    summary = json.loads((tmp_path / "bake.json").read_text())
    assert summary["warnings"] == [] and summary["objects"]["Floor"]["warnings"] == []


@pytest.mark.parametrize("method_args", [["--method", "rsm"], ["--method", "lpv", "--grid", "16"],
                                         ["--method", "vct", "--voxel-cells", "16", "--cones", "6"]])
def test_a_bake_solves_once_and_gathers_per_object(tmp_path, method_args):
    # The light field depends on the scene and its lights, not on the texels: the Cornell box's seven
    # objects take one solve, and each object only its gather.
    blend = tmp_path / "cornell.blend"
    assert cli("scene", "cornell", "--out", str(blend)).returncode == 0
    r = cli("bake", str(blend), "--out", str(tmp_path / "out"), *FAST, *method_args)
    assert r.returncode == 0, r.stderr
    summary = json.loads((tmp_path / "out" / "bake.json").read_text())
    objects = summary["objects"].values()
    assert len(objects) == 7 and summary["solves"] == 1
    assert sum(o["solve_ms"] > 0 for o in objects) == 1  # the first object's update solved
    assert all(o["gather_ms"] > 0 for o in objects)


def test_a_supersampled_texel_is_the_mean_of_its_covered_sub_texels(blend, tmp_path):
    # --supersample 2 at 16 texels bakes the same 32 x 32 sub-texels as a plain bake at 32 (the same
    # G-buffer, the same light) and gives each texel the mean of its covered ones (lightmap.block_mean):
    # equal to that mean of the 32-texel bake to fp32 rounding, on every texel either covers, away from
    # the islands' edges (there the bake tells sub-texels the surface only touches from those whose
    # centres it covers, which the written alpha does not: tests/unit/test_lightmap.py holds that rule).
    # The spot's edge crosses the Floor, so texels between lit and dark take values between.
    from addon.bridge import images
    from addon.engine.lightmap import block_mean

    light = ["--rsm-res", "32", "--vpl-samples", "4", "--visibility", "none", "--quiet", "--method", "direct",
             "--pass", "direct", "--objects", "Floor", "--margin", "0"]
    for size, factor in ((16, 2), (32, 1)):
        r = cli("bake", str(blend), "--out", str(tmp_path / f"s{size}"), "--size", str(size), "--supersample",
                str(factor), *light)
        assert r.returncode == 0, r.stderr
    fine = images.read_exr(tmp_path / "s32" / "Floor_direct.exr")
    coarse = images.read_exr(tmp_path / "s16" / "Floor_direct.exr")
    expected = block_mean(fine, 2)
    covered = expected[..., 3] > 0.5
    assert covered.mean() > 0.5 and (coarse[..., 3] > 0.5).sum() == covered.sum()
    # A touched-only sub-texel has an uncovered 4-neighbour (the islands are rectangles): blocks whose
    # sub-texels have none hold only centre-covered ones.
    inner = np.pad(fine[..., 3] > 0.5, 1)
    inner = inner[1:-1, 1:-1] & inner[:-2, 1:-1] & inner[2:, 1:-1] & inner[1:-1, :-2] & inner[1:-1, 2:]
    interior = inner.reshape(16, 2, 16, 2).all(axis=(1, 3))
    assert interior.sum() > 0.5 * covered.sum()
    np.testing.assert_allclose(coarse[interior], expected[interior], rtol=1e-5, atol=1e-6)
    lit = fine[..., :3].max()
    between = (coarse[interior][:, :3].max(axis=1) > 0.05 * lit) & (coarse[interior][:, :3].max(axis=1) < 0.95 * lit)
    assert between.any()


def test_self_check_estimates_each_lightmaps_error_against_cycles(tmp_path):
    # bake --self-check: each lightmap's path-traced estimate (two few-sample Cycles bakes of the object,
    # their noise subtracted) must lie within the issue's factor 1.5 of its error against Cycles' bake at
    # 1024 spp (its own noise: the Floor's 256-spp bake reads a noise floor of 0.008 at 64 texels,
    # tests/e2e/test_bake_vs_cycles.py). The Floor, lit by the spot and the walls, at 32 x 32 texels.
    import bpy

    from addon.bridge import images, scenes
    from addon.bridge.reference import cycles_bake
    from addon.engine.metrics import rel_rmse_8

    path = tmp_path / "cornell.blend"
    scenes.save("cornell", path)
    out = tmp_path / "out"
    r = cli("bake", str(path), "--out", str(out), "--objects", "Floor", "--size", "32", "--method", "lpv",
            "--self-check", "--quiet")
    assert r.returncode == 0, r.stderr
    check = json.loads((out / "bake.json").read_text())["objects"]["Floor"]["self_check"]
    assert check["check_spp"] >= 4 and check["check_time_s"] > 0 and check["check_noise"] > 0
    ours = images.read_exr(out / "Floor_indirect.exr")
    bpy.ops.wm.open_mainfile(filepath=str(path))
    ref, _ = cycles_bake("Floor", {"INDIRECT"}, 1024, seed=0, size=32)
    measured = rel_rmse_8(ours[..., :3], ref[..., :3], (ours[..., 3] > 0.5) & (ref[..., 3] > 0.5))
    assert 1 / 1.5 <= check["estimated_rel_rmse_8"] / measured <= 1.5, (check, measured)
