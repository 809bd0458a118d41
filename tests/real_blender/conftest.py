"""The real-Blender tier: Debian trixie's Blender 4.3 binary in a chroot (tools/real_blender.py), the
extension installed from its zip as a user installs it, scripts run inside that Blender in background
mode and in a real window on Xvfb. `make test-blender` runs it; `make test` leaves it out (it needs root
and sets up a 1.8 GB root on first use).

Paths: each test session gets a folder under the root's /bounce (seen from the host under .cache/),
holding the zip, the scripts, a Blender home with the installed extension, scenes and results.
"""

from __future__ import annotations

import json
import shutil
import subprocess
import sys
import uuid
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(REPO / "tools"))
import real_blender  # noqa: E402

SCRIPTS = Path(__file__).resolve().parent / "blender_scripts"


class RealBlender:
    """One session's folder inside the root, and ways to run Blender scripts there."""

    def __init__(self, zip_path: Path):
        self.inside = f"{real_blender.WORK}/{uuid.uuid4().hex[:8]}"  # as Blender sees it
        self.host = real_blender.host_path(self.inside)
        shutil.copytree(SCRIPTS, self.host / "scripts")
        shutil.copy(zip_path, self.host / "bounce.zip")
        self.home = f"{self.inside}/home"  # the user's Blender config: the installed extension

    def path(self, name: str) -> tuple[str, Path]:
        """(path inside the root, the same on the host) of a file in this session's folder."""
        return f"{self.inside}/{name}", self.host / name

    def script(self, name: str, args: list[str], blend: str | None = None, window: bool = False,
               home: str | None = None, timeout_s: float = 600) -> dict:
        """Run scripts/NAME inside Blender (background unless window); return its JSON result."""
        result_in, result_host = self.path(f"{Path(name).stem}-{uuid.uuid4().hex[:6]}.json")
        argv = ([blend] if blend else []) + ["--python", f"{self.inside}/scripts/{name}", "--", *args, result_in]
        home = home or self.home
        if window:
            proc = real_blender.window(argv, home, timeout_s)
        else:
            proc = real_blender.run_blender(["--background", *argv], home, timeout_s)
        log = f"blender exit {proc.returncode}\n--- stdout\n{proc.stdout[-6000:]}\n--- stderr\n{proc.stderr[-3000:]}"
        assert result_host.is_file(), log
        result = json.loads(result_host.read_text())
        assert result.get("ok"), result.get("traceback", result) if result.get("traceback") else log
        return result


@pytest.fixture(scope="session")
def real(tmp_path_factory) -> RealBlender:
    try:
        real_blender.ensure()
    except (real_blender.SetupError, subprocess.CalledProcessError) as exc:
        pytest.fail(f"real Blender set-up failed: {exc}")
    sys.path.insert(0, str(REPO / "tools"))
    import build_extension

    dist = tmp_path_factory.mktemp("dist")
    zips = build_extension.build_all(dist)
    session = RealBlender(next(z for z in zips if z.name.endswith("linux_x64.zip")))
    yield session
    shutil.rmtree(session.host, ignore_errors=True)


@pytest.fixture(scope="session")
def installed(real) -> dict:
    """The zip installed into the session's Blender home (preferences saved): install.py's result."""
    return real.script("install.py", [f"{real.inside}/bounce.zip"])


@pytest.fixture(scope="session")
def cornell_blend(real, installed) -> str:
    """The Cornell box saved by this Blender (path inside the root)."""
    inside, _ = real.path("cornell.blend")
    real.script("scene.py", ["cornell", inside])
    return inside
