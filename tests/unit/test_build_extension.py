"""The extension zip's allow-list: what a user leaves in the checkout (the README's own example writes
c.blend, ref/ and ours/ there) must never reach a zip."""

from __future__ import annotations

import importlib.util
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]


def _build_module():
    spec = importlib.util.spec_from_file_location("build_extension", ROOT / "tools" / "build_extension.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_stage_copies_only_the_addon(tmp_path):
    build = _build_module()
    src, dest = tmp_path / "src", tmp_path / "dest"
    kept = ["__init__.py", "blender_manifest.toml", "addon/cli.py", "addon/engine/sh.py", "operators/bake.py",
            "panels/main.py", "gpu_shaders/lpv/inject.frag.glsl"]
    strays = ["c.blend", "ref/indirect.exr", "ours/stats.json", "out/demo/report.md", "addon/c.blend",
              "addon/__pycache__/cli.cpython-311.pyc", "addon/engine/notes.txt", "Makefile", "tests/test_x.py",
              ".venv/bin/python", "dist/old.zip", "gpu_shaders/lpv/dump.exr"]
    for rel in kept + strays:
        (src / rel).parent.mkdir(parents=True, exist_ok=True)
        (src / rel).write_text("x")
    (src / "wheels").mkdir()
    (src / "wheels" / "moderngl-5.13.0-cp311-cp311-win_amd64.whl").write_text("x")
    dest.mkdir()
    build.stage(src, dest)
    staged = sorted(str(p.relative_to(dest)) for p in dest.rglob("*") if p.is_file())
    assert staged == sorted([*kept, "wheels/moderngl-5.13.0-cp311-cp311-win_amd64.whl"])


def test_allow_list_covers_the_addon_sources():
    # Every tracked-looking source of the add-on is allowed: a new package folder would be caught here.
    build = _build_module()
    allowed = {str(p) for p in build.allowed_paths(ROOT)}
    for folder in ("addon", "operators", "panels"):
        for path in (ROOT / folder).rglob("*.py"):
            assert str(path.relative_to(ROOT)) in allowed
    assert "addon/registration.py" in allowed and "gpu_shaders/common/sh.glsl" in allowed
