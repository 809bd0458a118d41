"""A real Blender binary for the tests: Debian trixie's `blender` package (4.3) in a chroot under .cache/.

The project's machines run Debian 12, whose own Blender (3.4) predates extensions, so the binary comes
from Debian trixie, installed by package name into a `debootstrap --variant=minbase` root with Xvfb,
Mesa (llvmpipe: OpenGL 4.5 without a GPU), xwd and ImageMagick for screenshots. Setting up takes about
two minutes and 1.8 GB once; later calls find the stamp and return at once. Needs root (chroot, mount).

    python tools/real_blender.py setup                 # idempotent
    python tools/real_blender.py run -- --version      # blender with these arguments, in the chroot

The tests (tests/real_blender) use `ensure()`, `run_blender()` and `window()` from here. Only /proc is
mounted into the root, and only while a command runs: a leftover bind mount of /dev or /sys inside the
checkout would make deleting .cache/ dangerous.
"""

from __future__ import annotations

import argparse
import contextlib
import os
import shutil
import subprocess
import sys
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
ROOT = REPO / ".cache" / "real-blender" / "root"
STAMP = ROOT.parent / "installed"
SUITE = "trixie"
# Blender, a virtual screen, Mesa's software GL/EGL, xwd (screen grabs) and ImageMagick (xwd -> PNG).
PACKAGES = ("blender", "xvfb", "xauth", "x11-apps", "imagemagick", "libgl1-mesa-dri", "libegl1", "libegl-mesa0",
            "python3-numpy")
WORK = "/bounce"  # inside the root: where tests put zips, scripts and results
# By absolute path: the commands below run with the root's clean PATH, which is looked up on the host.
CHROOT = shutil.which("chroot", path=os.environ.get("PATH", "") + ":/usr/sbin:/sbin") or "/usr/sbin/chroot"


class SetupError(Exception):
    pass


def _run(cmd: list[str], **kwargs) -> subprocess.CompletedProcess:
    return subprocess.run(cmd, check=True, **kwargs)


@contextlib.contextmanager
def _proc_mounted():
    target = ROOT / "proc"
    mounted = os.path.ismount(target)
    if not mounted:
        _run(["mount", "-t", "proc", "proc", str(target)])
    try:
        yield
    finally:
        if not mounted:
            subprocess.run(["umount", "-l", str(target)], check=False)


def ensure(log=sys.stderr) -> Path:
    """Set the root up unless the stamp says it is; return the root."""
    if STAMP.is_file():
        return ROOT
    if os.geteuid() != 0:
        raise SetupError("the real-Blender tier needs root (debootstrap, chroot, mount)")
    t0 = time.perf_counter()
    if shutil.which("debootstrap") is None:
        print("real-blender: installing debootstrap", file=log)
        _run(["apt-get", "update", "-qq"])
        _run(["apt-get", "install", "-y", "-qq", "debootstrap"],
             env={**os.environ, "DEBIAN_FRONTEND": "noninteractive"})
    if ROOT.exists():  # a set-up that stopped half-way: start again
        shutil.rmtree(ROOT)
    ROOT.parent.mkdir(parents=True, exist_ok=True)
    print(f"real-blender: debootstrap {SUITE} into {ROOT} (about a minute)", file=log)
    _run(["debootstrap", "--variant=minbase", SUITE, str(ROOT)], stdout=subprocess.DEVNULL)
    shutil.copy("/etc/resolv.conf", ROOT / "etc" / "resolv.conf")
    print(f"real-blender: apt-get install {' '.join(PACKAGES)} (about a minute)", file=log)
    with _proc_mounted():
        env = {"PATH": "/usr/sbin:/usr/bin:/sbin:/bin", "DEBIAN_FRONTEND": "noninteractive"}
        _run([CHROOT, str(ROOT), "apt-get", "update", "-qq"], env=env)
        _run([CHROOT, str(ROOT), "apt-get", "install", "-y", "-qq", "--no-install-recommends", *PACKAGES],
             env=env, stdout=subprocess.DEVNULL)
        _run([CHROOT, str(ROOT), "apt-get", "clean"], env=env)
    (ROOT / WORK.lstrip("/")).mkdir(exist_ok=True)
    STAMP.write_text(blender_version() + "\n")
    print(f"real-blender: ready in {time.perf_counter() - t0:.0f} s: {STAMP.read_text().strip()}", file=log)
    return ROOT


def host_path(path_in_root: str) -> Path:
    """Where a path inside the root lies on this machine."""
    return ROOT / path_in_root.lstrip("/")


def _env(home: str, extra: dict | None = None) -> dict:
    # A clean environment: the host's PYTHONPATH or venv must not leak into Blender's Python. The user
    # resources and extensions live under `home`, so each test starts from an empty Blender config.
    return {"PATH": "/usr/bin:/bin", "HOME": home, "LANG": "C.UTF-8",
            "BLENDER_USER_RESOURCES": f"{home}/resources", "BLENDER_USER_EXTENSIONS": f"{home}/extensions",
            **(extra or {})}


def run_blender(args: list[str], home: str, timeout_s: float = 600, extra_env: dict | None = None,
                ) -> subprocess.CompletedProcess:
    """`blender ARGS` inside the root (paths in ARGS are the root's), output captured as text."""
    with _proc_mounted():
        return subprocess.run([CHROOT, str(ROOT), "blender", *args], env=_env(home, extra_env),
                              capture_output=True, text=True, timeout=timeout_s)


def window(args: list[str], home: str, timeout_s: float = 600, size=(1280, 800),
           extra_env: dict | None = None) -> subprocess.CompletedProcess:
    """Blender in a real window on a fresh Xvfb screen inside the root (DISPLAY is in its environment)."""
    display = f":{50 + os.getpid() % 200}"
    script = (f"Xvfb {display} -screen 0 {size[0]}x{size[1]}x24 -nolisten tcp >/dev/null 2>&1 & X=$!; "
              f"for i in $(seq 50); do [ -e /tmp/.X11-unix/X{display[1:]} ] && break; sleep 0.1; done; "
              f"DISPLAY={display} blender --window-geometry 0 0 {size[0]} {size[1]} --no-window-focus \"$@\"; "
              "rc=$?; kill $X; exit $rc")
    with _proc_mounted():
        return subprocess.run([CHROOT, str(ROOT), "bash", "-c", script, "window", *args],
                              env=_env(home, {"BOUNCE_DISPLAY": display, **(extra_env or {})}),
                              capture_output=True, text=True, timeout=timeout_s)


def blender_version() -> str:
    out = run_blender(["--version"], "/tmp", timeout_s=60).stdout
    return out.strip().splitlines()[0] if out.strip() else "unknown"


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    sub = parser.add_subparsers(dest="command", required=True)
    sub.add_parser("setup", help="set the root up (idempotent)")
    run = sub.add_parser("run", help="run blender in the root with the arguments after --")
    run.add_argument("args", nargs=argparse.REMAINDER)
    args = parser.parse_args(argv)
    try:
        ensure()
    except (SetupError, subprocess.CalledProcessError) as exc:
        print(f"error: real-blender set-up failed: {exc}", file=sys.stderr)
        return 2
    if args.command == "run":
        extra = args.args[1:] if args.args[:1] == ["--"] else args.args
        result = run_blender(extra, "/tmp")
        sys.stdout.write(result.stdout)
        sys.stderr.write(result.stderr)
        return result.returncode
    print(STAMP.read_text().strip())
    return 0


if __name__ == "__main__":
    sys.exit(main())
