"""Shared by the scripts that tests/real_blender runs inside a real Blender (its own Python, not the venv).

Each script takes its arguments after `--` and writes one JSON result file; an exception is written
there too (with its traceback), so the test on the host reports what went wrong inside Blender.
"""

import importlib
import json
import sys
import traceback

import bpy

PACKAGE = "bl_ext.user_default.bounce"


def args() -> list[str]:
    return sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []


def bounce(module: str):
    """A module of the installed extension, e.g. bounce("addon.bridge.live")."""
    return importlib.import_module(f"{PACKAGE}.{module}")


def write(path: str, result: dict) -> None:
    with open(path, "w") as f:
        json.dump(result, f, indent=1)


def main(fn, result_path: str) -> None:
    """Run fn(result) and write result (with the error, if any); exit non-zero on an error."""
    result = {"blender": bpy.app.version_string}
    try:
        fn(result)
        result["ok"] = True
    except Exception as exc:
        result.update(ok=False, error=f"{type(exc).__name__}: {exc}", traceback=traceback.format_exc())
    write(result_path, result)
    if not result["ok"]:
        sys.exit(1)


def image_stats(img) -> dict:
    import numpy as np

    px = np.empty(len(img.pixels), np.float32)
    img.pixels.foreach_get(px)
    rgb = px.reshape(-1, 4)[:, :3]
    return {"size": list(img.size), "packed": img.packed_file is not None, "users": img.users,
            "finite": bool(np.isfinite(rgb).all()), "min": float(rgb.min()), "mean": float(rgb.mean()),
            "max": float(rgb.max())}
