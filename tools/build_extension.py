"""Build the Blender extension zips: dist/bounce-<version>-<platform>.zip, one per platform.

1. Download the binary wheels of moderngl and glcontext for every Python that Blender 4.2+ ships
   (3.11 up to 5.0, 3.13 from 5.1) and every platform of the manifest into wheels/.
2. Write that list into the manifest's `wheels`, so the manifest never names a wheel we did not fetch.
3. Copy the add-on's own files, by an allow-list (`ALLOWED`), into a staging folder, so nothing a user or
   a test leaves in the checkout (c.blend, ref/, out/, caches) can reach a zip.
4. Build from that folder with Blender's own packaging tool (shipped inside the bpy module), which
   validates the manifest and puts only each platform's wheels into its zip.

Usage: python tools/build_extension.py --out dist
"""

from __future__ import annotations

import argparse
import importlib.util
import re
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
MANIFEST = ROOT / "blender_manifest.toml"
WHEELS_DIR = ROOT / "wheels"

PACKAGES = ("moderngl==5.13.0", "glcontext==3.1.0")
PYTHON_VERSIONS = ("3.11", "3.13")
# Blender platform -> pip platform tag. manylinux2014 rather than manylinux_2_17: pip expands the legacy
# alias down to manylinux1, which is what glcontext 3.1.0 publishes; the PEP 600 spelling does not.
PIP_PLATFORMS = {
    "linux-x64": "manylinux2014_x86_64",
    "windows-x64": "win_amd64",
    "macos-arm64": "macosx_11_0_arm64",
}

# What a zip holds: root file -> itself, package folder -> its files with these suffixes (no caches, no
# data a user may have saved inside). The wheels are added from wheels/ by the manifest's list.
ALLOWED_FILES = ("__init__.py", "blender_manifest.toml")
ALLOWED_DIRS = {"addon": (".py", ".json"), "operators": (".py",), "panels": (".py",), "gpu_shaders": (".glsl",)}

_WHEELS_BLOCK = re.compile(r"^wheels = \[.*?^\]", re.MULTILINE | re.DOTALL)


class BuildError(Exception):
    pass


def blender_ext_script() -> Path:
    # The bpy module bundles Blender's scripts beside itself; find_spec locates it without importing it.
    spec = importlib.util.find_spec("bpy")
    if spec is None or spec.origin is None:
        raise BuildError("the bpy module is not installed: `pip install bpy` (it ships blender_ext.py)")
    bpy_dir = Path(spec.origin).parent
    matches = sorted(bpy_dir.glob("*/scripts/addons_core/bl_pkg/cli/blender_ext.py"))
    if not matches:
        raise BuildError(f"blender_ext.py not found under {bpy_dir}")
    return matches[-1]


def download_wheels() -> list[str]:
    """Fetch the wheels; return their manifest paths (./wheels/NAME.whl), sorted."""
    WHEELS_DIR.mkdir(exist_ok=True)
    for python_version in PYTHON_VERSIONS:
        for pip_platform in PIP_PLATFORMS.values():
            cmd = [
                sys.executable,
                "-m",
                "pip",
                "download",
                "--quiet",
                "--disable-pip-version-check",
                "--only-binary=:all:",
                "--no-deps",
                "--python-version",
                python_version,
                "--platform",
                pip_platform,
                "-d",
                str(WHEELS_DIR),
                *PACKAGES,
            ]
            result = subprocess.run(cmd, capture_output=True, text=True)
            if result.returncode != 0:
                raise BuildError(
                    f"pip download failed for Python {python_version} on {pip_platform}:\n" + result.stderr.strip()
                )
    # Only the pinned versions: an old download left in wheels/ must not slip into the manifest.
    stems = tuple(p.replace("==", "-") + "-" for p in PACKAGES)
    names = sorted(p.name for p in WHEELS_DIR.glob("*.whl") if p.name.startswith(stems))
    expected = len(PACKAGES) * len(PYTHON_VERSIONS) * len(PIP_PLATFORMS)
    if len(names) != expected:
        raise BuildError(f"expected {expected} wheels in {WHEELS_DIR}, found {len(names)}: {names}")
    return [f"./wheels/{name}" for name in names]


def write_manifest_wheels(wheels: list[str]) -> bool:
    """Replace the manifest's `wheels = [...]` block; return whether it changed."""
    text = MANIFEST.read_text(encoding="utf-8")
    block = "wheels = [\n" + "".join(f'  "{w}",\n' for w in wheels) + "]"
    new_text, count = _WHEELS_BLOCK.subn(block, text)
    if count != 1:
        raise BuildError(f"{MANIFEST.name}: expected one 'wheels = [' ... ']' block, found {count}")
    if new_text == text:
        return False
    MANIFEST.write_text(new_text, encoding="utf-8")
    return True


def allowed_paths(root: Path) -> list[Path]:
    """The add-on's files under `root`, relative to it, sorted: what a zip may hold besides wheels."""
    paths = [Path(name) for name in ALLOWED_FILES if (root / name).is_file()]
    for folder, suffixes in ALLOWED_DIRS.items():
        for path in sorted((root / folder).rglob("*")):
            rel = path.relative_to(root)
            if path.is_file() and path.suffix in suffixes and "__pycache__" not in rel.parts:
                paths.append(rel)
    return sorted(paths)


def stage(root: Path, dest: Path) -> None:
    """Copy the allowed files and the wheels of root into dest (the build's source folder)."""
    for rel in allowed_paths(root):
        (dest / rel).parent.mkdir(parents=True, exist_ok=True)
        shutil.copy2(root / rel, dest / rel)
    (dest / "wheels").mkdir()
    for wheel in (root / "wheels").glob("*.whl"):
        shutil.copy2(wheel, dest / "wheels" / wheel.name)


def build(out_dir: Path) -> list[Path]:
    out_dir.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(prefix="bounce-build-") as staging:
        stage(ROOT, Path(staging))
        cmd = [sys.executable, str(blender_ext_script()), "build", "--source-dir", staging,
               "--output-dir", str(out_dir.resolve()), "--split-platforms"]
        result = subprocess.run(cmd, capture_output=True, text=True)
    if result.returncode != 0:
        raise BuildError(f"blender_ext.py build failed:\n{result.stdout}{result.stderr}".strip())
    return sorted(out_dir.glob("bounce-*.zip"))


def build_all(out_dir: Path) -> list[Path]:
    """Wheels, manifest, zips: what `make extension` does; the zips' paths."""
    if write_manifest_wheels(download_wheels()):
        print(f"updated the wheels of {MANIFEST.name}: commit it", file=sys.stderr)
    return build(out_dir)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=ROOT / "dist", help="output folder for the zips")
    args = parser.parse_args(argv)
    try:
        for zip_path in build_all(args.out):
            print(zip_path)
    except BuildError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
