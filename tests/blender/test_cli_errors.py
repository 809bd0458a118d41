"""Failures found after Blender has loaded the file still leave nothing behind: the output directory a
failed run created is removed (it is empty), one existing before is kept."""

import subprocess
import sys
from pathlib import Path

import pytest

pytestmark = pytest.mark.blender
ROOT = Path(__file__).resolve().parents[2]


def cli(*args):
    return subprocess.run([sys.executable, "-m", "addon", *map(str, args)], cwd=ROOT, capture_output=True, text=True)


@pytest.fixture(scope="module")
def empty_blend(tmp_path_factory):
    path = tmp_path_factory.mktemp("scenes") / "empty.blend"
    code = ("import bpy; bpy.ops.wm.read_factory_settings(use_empty=True);"
            f"bpy.ops.wm.save_as_mainfile(filepath={str(path)!r})")
    subprocess.run([sys.executable, "-c", code], check=True, capture_output=True)
    return path


def error_lines(r):
    return [line for line in r.stderr.splitlines() if line.startswith("error:")]


@pytest.mark.parametrize(("command", "needle"), [
    (["render", "--method", "direct"], "has no camera"),
    (["bake", "--quiet"], "no objects to bake"),
])
def test_a_failed_run_removes_the_directory_it_created(empty_blend, tmp_path, command, needle):
    out = tmp_path / "new"  # bake creates DIR only when its parent exists
    r = cli(command[0], empty_blend, "--out", out, *command[1:])
    assert r.returncode == 2 and "Traceback" not in r.stderr
    assert len(error_lines(r)) == 1 and needle in error_lines(r)[0], r.stderr
    assert not out.exists()
    # A directory that existed before is kept, empty or not.
    out.mkdir()
    assert cli(command[0], empty_blend, "--out", out, *command[1:]).returncode == 2
    assert out.is_dir()


def test_screenshot_views_are_the_overlays():
    from addon.bridge import viewport
    from addon.commands import screenshot

    assert set(screenshot.VIEWS) == set(viewport.MODE_WEIGHTS)
