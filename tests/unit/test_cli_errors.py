"""Bad input on the command line: exit 2, exactly one line on stderr naming the flag as it was typed, and
no output directory left behind. Every case here is refused before Blender is imported, so the CLI runs
in-process (addon.cli.main)."""

from pathlib import Path

import numpy as np
import pytest

from addon.cli import main
from addon.commands._args import removed_on_failure


def run_cli(capsys, *args) -> tuple[int, list[str]]:
    code = main([str(a) for a in args])
    return code, capsys.readouterr().err.strip().splitlines()


@pytest.fixture
def blend(tmp_path) -> Path:
    path = tmp_path / "scene.blend"
    path.write_bytes(b"BLENDER")  # never opened: every case fails before Blender loads
    return path


def assert_refused(code, lines, *needles):
    assert code == 2
    assert len(lines) == 1 and lines[0].startswith("error: "), lines
    for needle in needles:
        assert needle in lines[0], lines[0]


CONFIG_CASES = [
    (["--grid", "3"], "--grid 3: out of range [8, 256]"),
    (["--grid-cells", "3"], "--grid-cells 3: out of range [8, 256]"),
    (["--cones", "x"], "--cones x: must be an integer in [3, 32]"),
    (["--cone-offset", "nan"], "--cone-offset nan: out of range"),
    (["--visibility", "maybe"], "--visibility maybe: must be one of none, voxel"),
    (["--method", "magic"], "--method magic: must be one of direct, rsm, lpv, vct"),
    (["--variant", "new"], "--variant new: must be one of classic, improved"),
    (["--seed", "-1"], "--seed -1: out of range"),
    (["--res", "0"], "--res 0: out of range [8, 8192]"),
    (["--rsm-res", "8"], "--rsm-res 8: out of range [16, 4096]"),
    (["--voxel-cells", "512"], "--voxel-cells 512: out of range [8, 256]"),
    (["--method", "rsm", "--bounces", "2"], "--bounces 2: method rsm computes at most 1"),
]


@pytest.mark.parametrize("command", ["render", "bake"])
@pytest.mark.parametrize(("flags", "line"), CONFIG_CASES, ids=[" ".join(c[0]) for c in CONFIG_CASES])
def test_bad_setting_names_the_flag(capsys, tmp_path, blend, command, flags, line):
    out = tmp_path / "new" / "out"
    code, lines = run_cli(capsys, command, blend, "--out", out, *flags)
    assert_refused(code, lines, line)
    assert not (tmp_path / "new").exists()


@pytest.mark.parametrize(("flags", "needles"), [
    (["--target", "vertex-colors"], ["--target vertex-colors", "--save-blend"]),
    (["--target", "volume", "--method", "rsm"], ["--target volume", "--method lpv", "rsm"]),
    (["--target", "volume", "--size", "64"], ["--size", "--target volume"]),
    (["--target", "probes", "--method", "vct"], ["--target probes", "--method probes", "vct"]),
    (["--target", "probes", "--size", "64"], ["--size", "--target probes"]),
    (["--target", "volume", "--verify"], ["--verify", "--target image"]),
    (["--method", "direct"], ["--pass indirect", "--method direct"]),
    (["--method", "direct", "--pass", "combined"], ["--pass combined", "--method direct"]),
    (["--size", "4"], ["--size 4: out of range"]),
])
def test_bake_refuses_what_cannot_work_before_loading(capsys, tmp_path, blend, flags, needles):
    out = tmp_path / "new"
    code, lines = run_cli(capsys, "bake", blend, "--out", out, *flags)
    assert_refused(code, lines, *needles)
    assert not out.exists()


@pytest.mark.parametrize(("flags", "needles"), [
    (["--res", "2"], ["--res 2: out of range"]),
    (["--view", "FOO"], ["--view", "FOO"]),
    (["--method", "magic"], ["--method magic"]),
    (["--view", "VOXELS", "--method", "lpv"], ["--view VOXELS", "--method lpv", "rsm"]),
])
def test_screenshot_checks_its_arguments_first(capsys, tmp_path, flags, needles):
    out = tmp_path / "new"
    code, lines = run_cli(capsys, "screenshot", "--out", out, *flags)
    assert_refused(code, lines, *needles)
    assert not out.exists()


@pytest.mark.parametrize(("flags", "needle"), [
    (["--seed", "-1"], "--seed -1: out of range [0, 2147483647]"),
    (["--res", "4"], "--res 4: out of range"),
    (["--bounces", "9"], "--bounces 9: out of range [1, 8]"),
    (["--spp", "0"], "--spp"),
])
def test_reference_refuses_bad_values(capsys, tmp_path, blend, flags, needle):
    out = tmp_path / "new"
    code, lines = run_cli(capsys, "reference", blend, "--out", out, *flags)
    assert_refused(code, lines, needle)
    assert not out.exists()


@pytest.mark.parametrize("command", ["bench", "demo"])
def test_bench_and_demo_check_res(capsys, tmp_path, command):
    code, lines = run_cli(capsys, command, "--out", tmp_path / command, "--res", "4")
    assert_refused(code, lines, "--res 4: out of range")
    assert not (tmp_path / command).exists()


def write_png(path):
    import OpenImageIO as oiio

    out = oiio.ImageOutput.create(str(path))
    assert out.open(str(path), oiio.ImageSpec(8, 4, 3, oiio.UINT8))
    out.write_image(np.zeros((4, 8, 3), np.uint8))
    out.close()


def test_compare_refuses_display_encoded_images(capsys, tmp_path):
    from addon.bridge import images

    images.write_exr(tmp_path / "a.exr", np.ones((4, 8, 3), np.float32))
    write_png(tmp_path / "b.png")
    for pair in ((tmp_path / "a.exr", tmp_path / "b.png"), (tmp_path / "b.png", tmp_path / "a.exr")):
        code, lines = run_cli(capsys, "compare", *pair)
        assert_refused(code, lines, "b.png", "png", "linear EXR")
    code, _ = run_cli(capsys, "compare", tmp_path / "a.exr", tmp_path / "a.exr")
    assert code == 0


def test_a_failed_run_removes_only_the_directories_it_created(tmp_path):
    kept = tmp_path / "existed"
    kept.mkdir()
    new = kept / "a" / "b"
    with pytest.raises(RuntimeError), removed_on_failure(str(new)):
        new.mkdir(parents=True)
        raise RuntimeError
    assert kept.is_dir() and not (kept / "a").exists()
    # Anything written inside stays, and so does its directory.
    with removed_on_failure(str(new)) as report_status:
        new.mkdir(parents=True)
        (new / "bake.json").write_text("{}")
        report_status(2)
    assert (new / "bake.json").is_file()
    # A failure reported by exit status (no exception) cleans up as well.
    with removed_on_failure(str(tmp_path / "c")) as report_status:
        (tmp_path / "c").mkdir()
        report_status(2)
    assert not (tmp_path / "c").exists()
