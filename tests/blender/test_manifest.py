"""The extension manifest: valid for Blender's own tool, minimal permissions, wheels that match the pins
of tools/build_extension.py (one per package, Python version and platform)."""

from __future__ import annotations

import importlib.util
import subprocess
import sys
import tomllib
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
MANIFEST = ROOT / "blender_manifest.toml"


def _load_build_tool():
    spec = importlib.util.spec_from_file_location("build_extension", ROOT / "tools" / "build_extension.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _manifest() -> dict:
    with MANIFEST.open("rb") as fh:
        return tomllib.load(fh)


def test_blender_ext_validate_accepts_manifest():
    pytest.importorskip("bpy")
    tool = _load_build_tool().blender_ext_script()
    result = subprocess.run(
        [sys.executable, str(tool), "validate", str(ROOT)], capture_output=True, text=True, timeout=120
    )
    assert result.returncode == 0, result.stdout + result.stderr


def test_manifest_identity_and_only_files_permission():
    manifest = _manifest()
    assert (manifest["id"], manifest["type"], manifest["version"]) == ("bounce", "add-on", "0.2.0")
    assert manifest["blender_version_min"] == "4.2.0"
    assert list(manifest["permissions"]) == ["files"]
    assert manifest["permissions"]["files"].strip()


def _blender_platform(wheel_platform_tag: str) -> str:
    for prefix, platform in (("manylinux", "linux-x64"), ("win", "windows-x64"), ("macosx", "macos-arm64")):
        if wheel_platform_tag.startswith(prefix):
            return platform
    return wheel_platform_tag


def test_manifest_wheels_match_build_tool_pins():
    """Exactly one wheel per (pinned package, Python, platform); a pin bumped without rebuilding fails."""
    tool = _load_build_tool()
    manifest = _manifest()
    assert set(manifest["platforms"]) == set(tool.PIP_PLATFORMS)
    found = []
    for path in manifest["wheels"]:
        assert path.startswith("./wheels/") and path.endswith(".whl"), path
        # {name}-{version}-{python tag}-{abi tag}-{platform tag}.whl
        name, version, python_tag, _abi, platform_tag = Path(path).stem.split("-")
        found.append((f"{name}=={version}", python_tag, _blender_platform(platform_tag)))
    expected = [
        (pin, "cp" + python.replace(".", ""), platform)
        for pin in tool.PACKAGES
        for python in tool.PYTHON_VERSIONS
        for platform in tool.PIP_PLATFORMS
    ]
    assert sorted(found) == sorted(expected)
