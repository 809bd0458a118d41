"""Runs a method on a .blend headless: open, capture, run, write EXRs and stats.json.

Shared by `python -m addon render`, the demo and the benchmark. Outside Blender's UI the GPU work runs
on the moderngl backend (EGL), as ARCHITECTURE.md section 2 says.
"""

from __future__ import annotations

import json
import statistics
from collections.abc import Callable
from pathlib import Path

import bpy

from ..engine import methods
from ..engine.backends.moderngl_backend import ModernGLBackend
from ..engine.config import GIConfig, LpvConfig, RsmConfig, VctConfig
from ..engine.errors import SceneError
from . import images
from .capture import SceneCache, define_light_switch, image_size

_backend = None


def backend() -> ModernGLBackend:
    """One moderngl context per process: contexts are expensive and programs are cached on it."""
    global _backend
    if _backend is None:
        _backend = ModernGLBackend()
    return _backend


def open_blend(path: Path) -> None:
    try:
        bpy.ops.wm.open_mainfile(filepath=str(path), load_ui=False)
    except RuntimeError as exc:
        raise SceneError(f"cannot open {path}: {str(exc).strip().splitlines()[-1]}") from None


def render_file(blend: Path, out_dir: Path, gi: GIConfig, rsm: RsmConfig, repeat: int = 3,
                lpv: LpvConfig | None = None, vct: VctConfig | None = None,
                progress: Callable[[str], None] = lambda step: None) -> dict:
    """Render `blend` with gi.method; write <product>.exr for each product and stats.json; return stats.

    The timing is the median of `repeat` full updates after one warm-up (programs compiled, geometry
    uploaded): what a user waits for when a light moves. `progress(step)` is told each step.
    """
    progress(f"opening {blend}")
    open_blend(blend)
    define_light_switch()  # read the per-light include switch saved in the file
    scene = bpy.context.scene
    if scene.camera is None:
        raise SceneError(f"{blend}: the scene has no camera")
    width, height = image_size(scene, gi.resolution)
    captured = SceneCache().update(bpy.context.evaluated_depsgraph_get(), width, height)
    progress(f"method {gi.method}: uploading {captured.triangle_count} triangles, warm-up run (compiles shaders)")
    be = backend()
    method = methods.create(be, gi, rsm, lpv, vct)
    method.set_scene(captured)
    method.run()  # warm-up
    runs = []
    for i in range(repeat):
        progress(f"timed run {i + 1}/{repeat}")
        runs.append(method.run())
    result = runs[-1]
    progress(f"writing {out_dir}")
    for name, pixels in result.images.items():
        images.write_exr(out_dir / f"{name}.exr", pixels)
    notes = list(captured.warnings)
    if captured.triangle_count == 0:
        notes.append("the scene has no geometry: all light is zero")
    if not captured.lights and not captured.emission.any():
        notes.append("the scene has no light sources: all light is zero")
    stats = {
        "method": gi.method,
        "config": {"gi": gi.to_dict(), "rsm": rsm.to_dict(),
                   **({"lpv": method.lpv_config.to_dict()} if gi.method == "lpv" else {}),
                   **({"vct": method.vct_config.to_dict()} if gi.method == "vct" else {})},
        "image_size": [width, height],
        "triangles": captured.triangle_count,
        "lights": len(captured.lights),
        "timings_ms": {k: statistics.median(r.timings_ms[k] for r in runs) for k in result.timings_ms},
        "total_ms": statistics.median(r.timings_ms["total"] for r in runs),
        "runs": repeat,
        "renderer": be.renderer,
        "blender_version": bpy.app.version_string,
        "notes": notes,
    }
    (out_dir / "stats.json").write_text(json.dumps(stats, indent=2))
    return stats
