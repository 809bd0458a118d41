"""Runs a method on a .blend headless: open, capture, run, write EXRs and stats.json.

Shared by `python -m addon render`, the demo and the benchmark. Outside Blender's UI the GPU work runs
on the moderngl backend (EGL), as ARCHITECTURE.md section 2 says.
"""

from __future__ import annotations

import json
import statistics
from collections.abc import Callable
from dataclasses import replace
from pathlib import Path

import bpy
import numpy as np

from ..engine import choice, methods, registry
from ..engine.backends.moderngl_backend import ModernGLBackend
from ..engine.config import settings as complete_settings
from ..engine.errors import SceneError
from ..engine.updates import update_costs, update_costs_in_turn
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


def capture_blend(blend: Path, resolution: int):
    """Open `blend` and capture its scene for images `resolution` px on the long side; returns the
    captured scene and the image's (width, height)."""
    open_blend(blend)
    define_light_switch()  # read the per-light include switch saved in the file
    scene = bpy.context.scene
    if scene.camera is None:
        raise SceneError(f"{blend}: the scene has no camera")
    width, height = image_size(scene, resolution)
    return SceneCache().update(bpy.context.evaluated_depsgraph_get(), width, height), (width, height)


def methods_in_turn_update_costs(blend: Path, settings_list: list[dict], rounds: int) -> list[dict]:
    """updates.update_costs_in_turn for one method per {group: config} settings on `blend` (all at the
    first's resolution): each set up on the same captured scene and run once (shaders compiled, light field
    solved) before the rounds."""
    settings_list = [complete_settings(**settings) for settings in settings_list]
    captured, _ = capture_blend(blend, settings_list[0]["gi"].resolution)
    warm = []
    for settings in settings_list:
        method = methods.create(backend(), settings)
        method.set_scene(captured)
        method.run()
        warm.append(method)
    return update_costs_in_turn(warm, rounds)


def render_row(be, captured, settings: dict, model, key: str) -> np.ndarray:
    """The indirect image of the choice model's row `key` (`settings` with its setting) on the captured scene."""
    row = model.rows[key]
    method = methods.create(be, choice.apply_row(settings, row["method"], row["setting"]))
    method.set_scene(captured)
    return method.run().images["indirect"]


def camera_check_render(bounces: int, res: int):
    """choice.path_traced_check's `render` for the camera of the open scene: Cycles' Diffuse Indirect pass
    at `res` (reference.render_open, configured as the references are); it covers the pixels with
    geometry and a diffuse colour (as reference.reference_mask)."""
    from .reference import render_open

    def render(spp: int, seed: int) -> tuple[np.ndarray, np.ndarray, float]:
        layers, seconds, _ = render_open(spp, bounces, res, seed)
        mask = (layers["Combined"][..., 3] > 0.5) & (layers["Diffuse Color"][..., :3].max(axis=2) > 0)
        return layers["Diffuse Indirect"][..., :3], mask, seconds
    return render


def run_self_check(settings: dict, written: dict, progress) -> dict:
    """The run-time estimate of the rendered indirect image: choice's path-traced check, as precise as the
    error its pilot finds asks."""
    if "indirect" not in written:
        return {"note": "no self-check: the method makes no indirect light"}
    gi = settings["gi"]
    check = choice.path_traced_check(None, camera_check_render(gi.bounces, gi.resolution), progress,
                                     ours=written["indirect"])
    estimate = choice.path_traced_estimate(written["indirect"], check) if check is not None else None
    if estimate is None:
        return {"note": "no self-check: the image holds no diffuse surface"}
    return {"estimated_rel_rmse_8": estimate, **choice.check_stats(check)}


# --verify renders its candidates and its check at most this many pixels on the long side: the choice
# model was fitted at 128 px, and the check's Cycles samples per pixel do not fall as the pixels grow
# (rel_rmse_8 compares 8 x 8 blocks whatever their size), so at 1920 px it would cost ~200x 128 px's.
VERIFY_MAX_RESOLUTION = 256


def verify_choice(be, captured, requested: dict, settings: dict, decided: dict, error_budget: float,
                  progress: Callable[[str], None]) -> tuple[dict, dict]:
    """`--verify`: the candidates of choice.verify rendered on the captured scene and judged by one
    path-traced check (choice.path_traced_check, resolving `error_budget`), the first whose estimate is within
    the budget taken, else the one whose estimate is least (choice.least_estimated); both at most
    VERIFY_MAX_RESOLUTION px on the long side (the scene captured again at that size where the render is
    larger). Returns the settings to run (`requested` with that row's setting; the model's choice,
    `settings`, when no candidate could be tried) and `decided` with choice["verified"] = the rows tried,
    their estimates, the one accepted (None when none was within), the size they were judged at and the
    check's samples, noise and time."""
    model = choice.load()
    feats = decided["features"]
    able = registry.computing(requested["gi"].bounces)
    gi = requested["gi"]
    res = min(gi.resolution, VERIFY_MAX_RESOLUTION)
    if res < gi.resolution:
        progress(f"verify: capturing the scene at {res} px")
        width, height = image_size(bpy.context.scene, res)
        captured = SceneCache().update(bpy.context.evaluated_depsgraph_get(), width, height)
        requested = {**requested, "gi": replace(gi, resolution=res)}
    check = choice.path_traced_check(error_budget, camera_check_render(gi.bounces, res), progress)
    if check is None:
        decided["choice"]["verified"] = {"tried": [], "accepted": None,
                                         "note": "not verified: the image holds no diffuse surface"}
        return settings, decided

    def estimate(key: str) -> float | None:
        progress(f"verify: rendering {key}")
        return choice.path_traced_estimate(render_row(be, captured, requested, model, key), check)

    accepted, tried = choice.verify(model, feats, error_budget, estimate, able)
    settings, decided = choice.take_verified(model, feats, {**requested, "gi": gi}, settings, decided, error_budget,
                                             accepted, tried, {"resolution": res, **choice.check_stats(check)})
    if res < gi.resolution and decided.get("estimate_source") == "path-traced check":
        decided["estimate_resolution"] = res
    return settings, decided


def render_file(blend: Path, out_dir: Path, settings: dict, repeat: int = 3,
                progress: Callable[[str], None] = lambda step: None, profile_updates: bool = False,
                budget: dict | None = None, self_check: bool = False, verify: bool = False) -> dict:
    """Render `blend` with {group: config} settings (config.settings' form; missing groups take their
    defaults); write <product>.exr for each product and stats.json; return stats.

    The timing is the median of `repeat` full updates after one warm-up (programs compiled, geometry
    uploaded): what a user waits for when a light moves. `progress(step)` is told each step. With
    profile_updates, stats["update_ms"] holds `update_costs` (full, lights, camera) over `repeat` runs.
    budget ({"error_budget": E} or {"time_budget_ms": T}): the method and its settings are chosen for the
    captured scene (engine/choice.py) and stats["choice"] says which and why; every render's stats carry
    the choice model's `estimated_rel_rmse_8` where it knows the settings. self_check: also estimate the
    indirect image's error against Cycles on the scene itself (run_self_check: a few-sample Cycles pair
    whose own noise is subtracted; stats["self_check"]; that estimate becomes `estimated_rel_rmse_8`, the
    model's is kept as `model_estimated_rel_rmse_8`; `estimate_source` says which). verify (with an error budget): the
    choice is checked on the scene itself before it runs (verify_choice; stats["choice"]["verified"]).
    """
    settings = complete_settings(**settings)
    gi = settings["gi"]
    progress(f"opening {blend}")
    captured, (width, height) = capture_blend(blend, gi.resolution)
    if budget:
        progress("choosing the method for the budget")
    requested = settings
    settings, decided = choice.decide(captured, settings, width * height, **(budget or {}))
    be = backend()
    if verify and budget and "error_budget" in budget:
        settings, decided = verify_choice(be, captured, requested, settings, decided, budget["error_budget"], progress)
    gi = settings["gi"]
    progress(f"method {gi.method}: uploading {captured.triangle_count} triangles, warm-up run (compiles shaders)")
    method = methods.create(be, settings)
    method.set_scene(captured)
    method.run()  # warm-up
    runs = []
    for i in range(repeat):
        progress(f"timed run {i + 1}/{repeat}")
        runs.append(method.run())
    result = runs[-1]
    written = result.images
    refine_ms = 0.0
    if gi.samples > 1:  # the written images average gi.samples gathers (refine), timed apart
        progress(f"averaging {gi.samples} gathers")
        refine_ms = sum(method.refine().get("total", 0.0) for _ in range(gi.samples - 1))
        written = method.read()
    update_ms = None
    if profile_updates:
        progress(f"timing the three kinds of update ({repeat} of each)")
        update_ms = update_costs(method, max(repeat, 1))
    checked = None
    if self_check:
        progress("self-check: the path-traced check")
        checked = run_self_check(settings, written, progress)
        if checked.get("estimated_rel_rmse_8") is not None:
            # The run-time estimate replaces the model's, as with --verify: held out, it was within a factor
            # 1.5 of the measured error on every benchmark row, the model on 58 % (benchmarks/choice).
            decided = {**decided, "model_estimated_rel_rmse_8": decided.get("estimated_rel_rmse_8"),
                       "estimated_rel_rmse_8": checked["estimated_rel_rmse_8"],
                       "estimate_source": "path-traced check"}
    progress(f"writing {out_dir}")
    for name, pixels in written.items():
        images.write_exr(out_dir / f"{name}.exr", pixels)
    notes = list(captured.warnings)
    if captured.triangle_count == 0:
        notes.append("the scene has no geometry: all light is zero")
    if not captured.has_light_source():
        notes.append("the scene has no light sources: all light is zero")
    stats = {
        "method": gi.method,
        # The groups the method reads (registry): the shared groups and its own.
        "config": {group: settings[group].to_dict() for group in settings
                   if group in registry.SHARED_GROUPS or group in registry.get(gi.method).own_groups},
        "image_size": [width, height],
        "triangles": captured.triangle_count,
        "lights": len(captured.lights),
        "timings_ms": {k: statistics.median(r.timings_ms[k] for r in runs) for k in result.timings_ms},
        "total_ms": statistics.median(r.timings_ms["total"] for r in runs),
        "runs": repeat,
        "samples": gi.samples,
        "refine_ms": refine_ms,  # the gathers after the first, all together
        "work": method.work(),  # the method's own counts of its work (e.g. lpv's propagation cell-steps)
        **({"update_ms": update_ms} if update_ms is not None else {}),
        **{k: v for k, v in decided.items() if k != "features"},
        "scene_features": decided.get("features"),
        **({"self_check": checked} if checked is not None else {}),
        "renderer": be.renderer,
        "blender_version": bpy.app.version_string,
        "notes": notes,
    }
    (out_dir / "stats.json").write_text(json.dumps(stats, indent=2))
    return stats
