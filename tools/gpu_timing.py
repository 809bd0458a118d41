"""Full-update timings of every method on a real GPU at 1920 x 1080 (benchmarks/gpu/REPORT.md).

Two steps, because the GPU machine has no Blender:

    # here (bpy from .venv): capture the scenes into .npz + .json files the engine reads without bpy
    .venv/bin/python tools/gpu_timing.py export --out .gpubench
    # anywhere with moderngl and an EGL OpenGL 4.3 context (the GPU machine; llvmpipe for a smoke test)
    python3 tools/gpu_timing.py run --scenes .gpubench --out DIR [--res 1920x1080] [--repeat 20] [--budget-s S]

`run` times each (scene, method config: every registry benchmark row and EXTRA_ROWS) after `set_scene`
and 3 warm-up updates, every method's defaults on every scene first, then the other rows; with
--budget-s it starts none after S seconds:
  wall_total   compute() with method.profile off, then one backend.finish(): what an update costs
  update_ms    updates.update_costs: a geometry change, every light moved 1 cm, the camera moved 1 cm
  gpu          GL timestamp queries (glQueryCounter) around every pass, no waits between passes
  gpu_camera   the same for camera moves alone (the solve kept where the method keeps its light field)
  wall_pass_*  method.profile on: glFinish before and after every pass (stalls; per-pass upper bound)
  voxelize     a full re-voxelization (every layer redrawn: Voxelizer.invalidate, then run), GPU and wall
  *_fed        the voxelization and LPV's propagation with an update's GPU work queued ahead (fed_gpu_ms):
               their GPU work alone, where Python submits their many dispatches slower than the GPU runs them
It writes timings.json after every (scene, config) and timings.md at the end; `markdown JSON` rebuilds
the .md of a run cut short.

On a lent GPU machine (no moderngl, no GL loader there), after `tools/gpu_timing.py prepare` here:
the device tool's run with command `bash tools/gpu_device.sh` and carry [".gl", ".whl", ".gpubench"]
(its timing part took 327 s on an H200: every method's defaults on the four scenes, then some rows).
Raster passes (gbuffer, rsm, the injections, voxelize) are far slower on a compute GPU (H100, H200) than
on a graphics GPU: few of its units run vertex/fragment work. Its compute-pass figures are the
meaningful ones. The backend's GL context is made current once and kept current (a standalone
process), so no eglMakeCurrent per backend call is counted.
"""

from __future__ import annotations

import argparse
import ctypes
import ctypes.util
import dataclasses
import json
import platform
import sys
import time
import traceback
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

from addon.engine.updates import update_costs  # noqa: E402

SCENES = ("cornell", "cornell-glossy", "window-sky", "sponza")
SPONZA = Path("/work/shared/scenes/sponza/sponza.blend")
EXPORT_SIZE = (1920, 1080)
LPV_PASSES = ("lpv_inject", "lpv_propagate", "lpv_lookup")
VCT_PASSES = ("vct_inject", "vct_pyramid")  # + voxelize (timed apart) = the "voxelize + inject + filter"


# --------------------------------------------------------------------------------------- scene files

def _jsonable(value):
    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, np.generic):
        return value.item()
    return value


def save_scene(scene, path_stem: Path, meta: dict | None = None) -> dict:
    """Write `scene` (an engine Scene with a camera) as <stem>.npz (geometry, float32) and <stem>.json
    (lights, camera, world, warnings). Returns the json's content."""
    cam = scene.camera
    visible = scene.seen_by_camera()
    np.savez_compressed(
        path_stem.with_suffix(".npz"),
        positions_m=np.asarray(scene.positions_m, np.float32),
        normals=np.asarray(scene.normals, np.float32),
        albedo=np.asarray(scene.albedo, np.float32),
        bounce_albedo=scene.bounce_reflectance(),
        emission=np.asarray(scene.emission, np.float32),
        camera_visible=np.asarray(visible, bool),
        specular=scene.specular_f0(),
        roughness=scene.glossy_roughness(),
        **({} if scene.world_map is None else {"world_map": np.asarray(scene.world_map, np.float32)}),
    )
    info = {
        "lights": [{f.name: _jsonable(getattr(light, f.name)) for f in dataclasses.fields(light)}
                   for light in scene.lights],
        "world_color": _jsonable(np.asarray(scene.world_color, np.float64)),
        "camera": None if cam is None else {"view": cam.view.tolist(), "projection": cam.projection.tolist(),
                                            "width": cam.width, "height": cam.height},
        "warnings": list(scene.warnings),
        "triangles": scene.triangle_count,
        **(meta or {}),
    }
    path_stem.with_suffix(".json").write_text(json.dumps(info, indent=1))
    return info


def camera_at(camera, width: int, height: int):
    """`camera` resized to width x height; the projection keeps its horizontal field of view (exact when
    the aspect ratio is unchanged, as for 1920x1080 -> 320x180)."""
    from addon.engine.scene import Camera

    proj = np.array(camera.projection, np.float64)
    if (width, height) != (camera.width, camera.height):
        proj[1, 1] = proj[0, 0] * width / height
    return Camera(view=np.array(camera.view, np.float64), projection=proj, width=int(width), height=int(height))


def load_scene(path_stem: Path, size: tuple[int, int] | None = None):
    """The Scene saved by save_scene, its camera resized to `size` (None: as saved)."""
    from addon.engine.scene import Camera, Light, Scene

    info = json.loads(path_stem.with_suffix(".json").read_text())
    with np.load(path_stem.with_suffix(".npz")) as z:
        arrays = {k: z[k] for k in z.files}
    names = {f.name for f in dataclasses.fields(Light)}
    lights = [Light(**{k: (np.array(v) if isinstance(v, list) else v) for k, v in d.items() if k in names})
              for d in info["lights"]]
    cam = info.get("camera")
    camera = None
    if cam is not None:
        camera = Camera(view=np.array(cam["view"]), projection=np.array(cam["projection"]),
                        width=int(cam["width"]), height=int(cam["height"]))
        if size is not None:
            camera = camera_at(camera, *size)
    return Scene(positions_m=arrays["positions_m"], normals=arrays["normals"], albedo=arrays["albedo"],
                 emission=arrays["emission"], lights=lights,
                 world_color=np.array(info["world_color"], np.float32), camera=camera,
                 warnings=list(info.get("warnings", [])), camera_visible=arrays["camera_visible"],
                 specular=arrays.get("specular"), roughness=arrays.get("roughness"),  # absent in older exports
                 bounce_albedo=arrays.get("bounce_albedo"),
                 world_map=arrays.get("world_map"))


def export(out: Path, names: list[str]) -> None:
    """Build/open each scene in Blender, capture it at 1920x1080 and save it (needs bpy)."""
    import bpy

    from addon.bridge import scenes
    from addon.bridge.capture import SceneCache, define_light_switch
    from addon.bridge.pipeline import open_blend

    out.mkdir(parents=True, exist_ok=True)
    for name in names:
        if name == "sponza":
            if not SPONZA.exists():
                print(f"skip sponza: {SPONZA} not found", file=sys.stderr)
                continue
            open_blend(SPONZA)
            source = str(SPONZA)
        else:
            scenes.build(name)
            source = f"addon.bridge.scenes.build({name!r})"
        define_light_switch()
        captured = SceneCache().update(bpy.context.evaluated_depsgraph_get(), *EXPORT_SIZE)
        info = save_scene(captured, out / name, {"name": name, "source": source,
                                                 "blender_version": bpy.app.version_string})
        size = (out / f"{name}.npz").stat().st_size
        print(f"{name}: {info['triangles']} triangles, lights {[d['kind'] for d in info['lights']]}, "
              f"{size / 2**20:.2f} MiB")


# --------------------------------------------------------------------------------------- GL timers

class GpuTimestamps:
    """GL_TIMESTAMP queries (glQueryCounter) around each pass: GPU time per pass without stalling the
    pipeline. Functions come from eglGetProcAddress, so it works wherever the EGL context does."""

    GL_TIMESTAMP = 0x8E28
    GL_QUERY_RESULT = 0x8866

    def __init__(self):
        self.available = False
        self.error = ""
        try:
            egl = ctypes.CDLL(ctypes.util.find_library("EGL") or "libEGL.so.1")
            egl.eglGetProcAddress.restype = ctypes.c_void_p
            egl.eglGetProcAddress.argtypes = [ctypes.c_char_p]

            def fn(name, *argtypes):
                addr = egl.eglGetProcAddress(name.encode())
                if not addr:
                    raise RuntimeError(f"eglGetProcAddress({name}) failed")
                return ctypes.CFUNCTYPE(None, *argtypes)(addr)

            self._gen = fn("glGenQueries", ctypes.c_int, ctypes.POINTER(ctypes.c_uint))
            self._counter = fn("glQueryCounter", ctypes.c_uint, ctypes.c_uint)
            self._result = fn("glGetQueryObjectui64v", ctypes.c_uint, ctypes.c_uint,
                              ctypes.POINTER(ctypes.c_uint64))
            self._pool: list[int] = []
            self._used = 0
            self.records: list[tuple[str, int, int]] = []
            self.available = True
        except Exception as exc:  # noqa: BLE001 - reported, wall-clock timings still run
            self.error = f"{type(exc).__name__}: {exc}"

    def _query(self) -> int:
        if self._used == len(self._pool):
            ids = (ctypes.c_uint * 64)()
            self._gen(64, ids)
            self._pool.extend(int(i) for i in ids)
        q = self._pool[self._used]
        self._used += 1
        self._counter(q, self.GL_TIMESTAMP)
        return q

    def begin_update(self) -> None:
        self._used = 0
        self.records = []

    def timed(self, timings: dict, name: str):
        """Drop-in for method.timed: a context manager stamping the GPU timeline before and after."""
        import contextlib

        @contextlib.contextmanager
        def cm():
            q0 = self._query()
            yield
            self.records.append((name, q0, self._query()))

        return cm()

    def end_update(self) -> dict[str, float]:
        """Per-pass GPU ms of the update just finished (call after glFinish): passes summed over light
        faces; `total` the longest (outermost) span, as the methods nest their totals."""
        value = ctypes.c_uint64()
        out: dict[str, float] = {}
        for name, q0, q1 in self.records:
            self._result(q0, self.GL_QUERY_RESULT, ctypes.byref(value))
            t0 = value.value
            self._result(q1, self.GL_QUERY_RESULT, ctypes.byref(value))
            ms = (value.value - t0) / 1e6
            out[name] = max(out.get(name, 0.0), ms) if name == "total" else out.get(name, 0.0) + ms
        return out


# --------------------------------------------------------------------------------------- runs

# GPU-only rows beside the registry's benchmark rows: vct's real-time settings (few cones, a coarser
# gather), which the CPU benchmark does not run for their error but a GPU is timed on.
EXTRA_ROWS = {
    "vct": ({"vct.voxel_cells": 64, "vct.diffuse_cones": 6}, {"vct.voxel_cells": 64, "vct.diffuse_cones": 6,
                                                              "vct.gather_scale": 2},
            {"vct.voxel_cells": 128, "vct.diffuse_cones": 6, "vct.gather_scale": 2}),
}


def row_label(method: str, row: dict) -> str:
    """'lpv-grid_cells64-far_fieldFalse': the method and its row's settings, as a file-safe name."""
    return "-".join([method, *(f"{k.split('.', 1)[1]}{v}" for k, v in row.items())])


def configs(resolution: int = 1080) -> list[tuple[str, dict]]:
    """(label, {group: config}) of every method at every benchmark row of the registry (each method's
    defaults included) and EXTRA_ROWS: the same list of methods as everything else. The defaults are
    the viewport's, whose updates these time: the sky's auto rays take the filter there
    (sky_light.viewport_rays); a row that sets sky_rays keeps it."""
    from dataclasses import replace

    from addon.engine import choice, config, registry
    from addon.engine.passes import sky_light

    out = []
    for spec in registry.METHODS:
        rows = [{}, *(r for r in spec.bench if r), *EXTRA_ROWS.get(spec.name, ())]
        for row in rows:
            base = config.settings(gi=config.GIConfig(method=spec.name, resolution=resolution))
            base["rsm"] = replace(base["rsm"], sky_rays=sky_light.viewport_rays(base["rsm"].sky_rays))
            out.append((row_label(spec.name, row), choice.apply_row(base, spec.name, row)))
    return list(dict(out).items())  # a row equal to the defaults appears once


def make_method(be, settings: dict):
    from addon.engine import methods

    return methods.create(be, settings)


def summary(values: list[float]) -> dict:
    arr = np.asarray(values, np.float64)
    return {"median": float(np.median(arr)), "p90": float(np.percentile(arr, 90)), "min": float(arr.min()),
            "n": int(arr.size)}


def per_pass(runs: list[dict[str, float]]) -> dict[str, dict]:
    names = list(dict.fromkeys(k for r in runs for k in r))
    out = {k: summary([r.get(k, 0.0) for r in runs]) for k in names}
    lpv = [k for k in LPV_PASSES if k in names]
    if lpv:  # the LPV figure: injection + propagation + lookup
        out["lpv_inject+propagate+lookup"] = summary([sum(r.get(k, 0.0) for k in lpv) for r in runs])
    vct = [k for k in VCT_PASSES if k in names]
    if vct:
        out["vct_inject+pyramid"] = summary([sum(r.get(k, 0.0) for k in vct) for r in runs])
    return out


def time_method(be, method, scene, warmup: int, repeat: int, stamps: GpuTimestamps) -> dict:
    res: dict = {}
    be.finish()
    t0 = time.perf_counter()
    method.set_scene(scene)
    be.finish()
    res["set_scene_ms"] = (time.perf_counter() - t0) * 1e3

    # 1. what an update costs: no per-pass waits, one finish at the end
    method.profile = False
    for _ in range(warmup):
        method.compute(solve=True)
    be.finish()
    totals = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        method.compute(solve=True)
        be.finish()
        totals.append((time.perf_counter() - t0) * 1e3)
    res["wall_total"] = summary(totals)
    # the three kinds of update a user makes (a geometry change, lights moved, camera moved), medians
    res["update_ms"] = update_costs(method, repeat)

    # 2. GPU timestamps per pass (no waits between passes): a whole update, and a camera move alone (the
    # camera moved 1 cm and back, as update_costs moves it), so a camera update's passes are known too
    if stamps.available:
        method.profile = True
        method.timed = stamps.timed  # instance attribute shadows DirectMethod.timed
        camera = scene.camera
        view = camera.view.copy()
        view[0, 3] -= 0.01
        moved = dataclasses.replace(camera, view=view)
        try:
            for name, update in (("gpu", lambda i: method.compute(solve=True)),
                                 ("gpu_camera", lambda i: (method.set_camera(moved if i % 2 == 0 else camera),
                                                           method.compute()))):
                runs = []
                for i in range(warmup + repeat):
                    stamps.begin_update()
                    update(i)
                    be.finish()
                    r = stamps.end_update()
                    if i >= warmup:
                        runs.append(r)
                res[name] = per_pass(runs)
        finally:
            del method.timed
            method.set_camera(camera)

    # 3. method.profile: glFinish around every pass
    method.profile = True
    for _ in range(warmup):
        method.compute(solve=True)
    res["wall_profiled"] = per_pass([method.compute(solve=True) for _ in range(repeat)])

    # 4. a full re-voxelization alone (every layer redrawn, as after set_scene; a change in part of the scene
    # redraws only the layers it reaches)
    voxelizer = getattr(method, "voxelizer", None) or getattr(method, "_voxelizer", None)
    if voxelizer is not None:
        wall, gpu = [], []
        for i in range(warmup + repeat):
            if stamps.available:
                stamps.begin_update()
            voxelizer.invalidate()
            be.finish()
            t0 = time.perf_counter()
            if stamps.available:
                with stamps.timed({}, "voxelize"):
                    voxelizer.run()
            else:
                voxelizer.run()
            be.finish()
            if i >= warmup:
                wall.append((time.perf_counter() - t0) * 1e3)
                if stamps.available:
                    gpu.append(stamps.end_update()["voxelize"])
        res["voxelize"] = {"wall": summary(wall), **({"gpu": summary(gpu)} if gpu else {})}
        if stamps.available:
            res["voxelize_fed"] = fed_gpu_ms(be, stamps, method, lambda: (voxelizer.invalidate(), voxelizer.run()),
                                             warmup, repeat)

    # 5. LPV's propagation (finest grid) alone, fed: its ~100-190 dispatches are Python-bound on a slow host
    if stamps.available and hasattr(method, "propagate"):
        res["lpv_propagate_fed"] = fed_gpu_ms(be, stamps, method, method.propagate, warmup, repeat)
    res["gl_error"] = be.gl_error()
    return res


def fed_gpu_ms(be, stamps: GpuTimestamps, method, fn, warmup: int, repeat: int) -> dict:
    """GPU time of fn() with a whole update's GPU work queued ahead of it (method.compute(solve=True), not waited
    for), so that fn's commands are all submitted before the GPU reaches them: the timestamps then measure
    fn's GPU work, not how fast this host's Python submits many small dispatches or draws. Also returned:
    `submit_ms`, fn's submission (wall, no finish), and `ahead_gpu_ms`, the queued update's GPU time: the
    figure is fn's GPU work alone only while ahead_gpu_ms > submit_ms."""
    method.profile = False
    gpu, submit, ahead = [], [], []
    for i in range(warmup + repeat):
        stamps.begin_update()
        with stamps.timed({}, "ahead"):
            method.compute(solve=True)
        t0 = time.perf_counter()
        with stamps.timed({}, "fn"):
            fn()
        t1 = time.perf_counter()
        be.finish()
        r = stamps.end_update()
        if i >= warmup:
            gpu.append(r["fn"])
            ahead.append(r["ahead"])
            submit.append((t1 - t0) * 1e3)
    return {"gpu": summary(gpu), "submit_ms": summary(submit), "ahead_gpu_ms": summary(ahead)}


def run_order(scenes: list[str], rows: list[tuple[str, dict]]) -> list[tuple[str, tuple[str, dict]]]:
    """(scene, row) pairs: every method's defaults on every scene first, then the other rows, so a run cut
    short by its budget still holds each method's default figures."""
    defaults = [row for row in rows if "-" not in row[0]]  # row_label of a method's defaults: its name alone
    others = [row for row in rows if "-" in row[0]]
    return [(n, row) for row in defaults for n in scenes] + [(n, row) for row in others for n in scenes]


def run(scenes_dir: Path, out: Path, size: tuple[int, int], repeat: int, warmup: int,
        only_scenes: list[str] | None, only_configs: list[str] | None, budget_s: float | None = None) -> dict:
    from addon.engine.backends.moderngl_backend import ModernGLBackend

    out.mkdir(parents=True, exist_ok=True)
    be = ModernGLBackend()
    be.ctx.__enter__()  # keep the context current: the backend then skips eglMakeCurrent per call
    stamps = GpuTimestamps()
    report = {
        "renderer": be.renderer,
        "gl_vendor": be.ctx.info.get("GL_VENDOR"),
        "host": platform.node(),
        "python": platform.python_version(),
        "numpy": np.__version__,
        "moderngl": __import__("moderngl").__version__,
        "size": list(size),
        "warmup": warmup,
        "repeat": repeat,
        "timers": {
            "wall_total": "perf_counter around compute() with method.profile=False + one glFinish",
            "gpu": ("GL_TIMESTAMP queries (glQueryCounter) around every pass, no waits; "
                    + ("available" if stamps.available else f"UNAVAILABLE: {stamps.error}")),
            "wall_profiled": "method.profile=True: perf_counter with glFinish before/after every pass",
        },
        "context": "EGL context kept current for the whole process",
        "scenes": {},
    }
    print(f"renderer: {report['renderer']}; numpy {np.__version__}; gpu timers: {report['timers']['gpu']}",
          flush=True)
    stems = [p.with_suffix("") for p in sorted(scenes_dir.glob("*.npz"))
             if not only_scenes or p.stem in only_scenes]
    scenes = {stem.name: load_scene(stem, size) for stem in stems}
    for name, scene in scenes.items():
        report["scenes"][name] = {"triangles": scene.triangle_count,
                                  "lights": [light.kind for light in scene.lights], "configs": {}}
    rows = [(label, settings) for label, settings in configs(max(size))
            if not only_configs or label in only_configs]
    order = run_order(list(scenes), rows)
    start = time.perf_counter()
    for name, (label, settings) in order:
        if budget_s is not None and time.perf_counter() - start > budget_s:
            report["skipped_for_budget"] = report.get("skipped_for_budget", 0) + 1
            continue
        scene, entry = scenes[name], report["scenes"][name]
        t0 = time.perf_counter()
        try:
            method = make_method(be, settings)
            result = time_method(be, method, scene, warmup, repeat, stamps)
            result["config"] = {group: cfg.to_dict() for group, cfg in settings.items()}
            grid = getattr(method, "grid", None)
            if grid is not None:
                result["grid_dims"] = list(grid.dims)
            if hasattr(method, "lpv_config"):
                from addon.engine.methods.lpv import iterations_for, near_steps_for

                result["propagation_steps"] = iterations_for(method.lpv_config, method.grid)
                result["near_steps"] = near_steps_for(method.lpv_config, method.levels[-1].grid)
            del method
        except Exception as exc:  # noqa: BLE001 - one failing config must not lose the others
            result = {"error": f"{type(exc).__name__}: {exc}", "traceback": traceback.format_exc()}
        entry["configs"][label] = result
        gpu_total = result.get("gpu", {}).get("total", {}).get("median", float("nan"))
        msg = result.get("error") or (f"total {result['wall_total']['median']:.3f} ms wall, "
                                      f"gpu {gpu_total:.3f} ms")
        print(f"{name:8s} {label:24s} {msg}  ({time.perf_counter() - t0:.1f} s)", flush=True)
        (out / "timings.json").write_text(json.dumps(report, indent=1))
    (out / "timings.json").write_text(json.dumps(report, indent=1))
    (out / "timings.md").write_text(markdown(report))
    return report


def _fmt(stat: dict | None) -> str:
    return "-" if not stat else f"{stat['median']:.3f} / {stat['p90']:.3f}"


def markdown(report: dict) -> str:
    w, h = report["size"]
    lines = [f"# GPU timings at {w}x{h}", "",
             f"Renderer: {report['renderer']}; numpy {report['numpy']}, moderngl {report['moderngl']}; "
             f"{report['warmup']} warm-up + {report['repeat']} timed updates per config;",
             "",
             "Times in ms, median / p90. " + "; ".join(f"**{k}**: {v}" for k, v in report["timers"].items()) + ".",
             "",
             "Issue targets: LPV inject+propagate+lookup (GPU) <= 1 ms at 32^3, <= 3 ms at 64^3; VCT voxelize + "
             "inject + pyramid (GPU medians summed) <= 2 ms at 128^3 on sponza, vct_gather <= 2 ms.",
             "",
             "| scene | config | grid | set_scene | wall total | GPU total | GPU target passes | GPU voxelize (full) |",
             "| --- | --- | --- | --- | --- | --- | --- | --- |"]
    for scene, entry in report["scenes"].items():
        for label, r in entry["configs"].items():
            if "error" in r:
                lines.append(f"| {scene} | {label} | | ERROR: {r['error']} | | | | |")
                continue
            grid = "x".join(map(str, r["grid_dims"])) if "grid_dims" in r else ""
            if "propagation_steps" in r:
                grid += f" ({r['propagation_steps']} steps)"
            gpu = r.get("gpu", {})
            vox = r.get("voxelize", {}).get("gpu")
            target = ""
            if "lpv_inject+propagate+lookup" in gpu:
                target = f"inject+propagate+lookup {_fmt(gpu['lpv_inject+propagate+lookup'])}"
            elif "vct_inject+pyramid" in gpu:
                both = gpu["vct_inject+pyramid"]["median"] + (vox["median"] if vox else float("nan"))
                target = (f"voxelize+inject+pyramid {both:.3f}; gather {_fmt(gpu.get('vct_gather'))}")
            lines.append(f"| {scene} | {label} | {grid} | {r['set_scene_ms']:.1f} | {_fmt(r['wall_total'])} | "
                         f"{_fmt(gpu.get('total'))} | {target} | {_fmt(vox)} |")
    lines += ["", "## The three updates (wall ms, medians: a geometry change / every light moved 1 cm / the camera "
              "moved 1 cm; camera as a share of the geometry change)", "",
              "| scene | config | full | lights | camera | camera / full |", "| --- | --- | --- | --- | --- | --- |"]
    for scene, entry in report["scenes"].items():
        for label, r in entry["configs"].items():
            u = r.get("update_ms")
            if u:
                lines.append(f"| {scene} | {label} | {u['full']:.2f} | {u['lights']:.2f} | {u['camera']:.2f} | "
                             f"{100 * u['camera'] / u['full']:.0f} % |")
    lines += ["", "## Passes of many dispatches, fed (fed_gpu_ms): GPU work | Python submission | GPU work queued "
              "ahead (ms, medians; the first is the pass's GPU work alone where the third exceeds the second)", ""]
    for scene, entry in report["scenes"].items():
        for label, r in entry["configs"].items():
            for key in ("voxelize_fed", "lpv_propagate_fed"):
                if key in r:
                    f = r[key]
                    lines.append(f"- {scene} / {label} / {key.removesuffix('_fed')}: {f['gpu']['median']:.3f} | "
                                 f"{f['submit_ms']['median']:.3f} | {f['ahead_gpu_ms']['median']:.3f}")
    lines += ["", "## Per pass (median / p90 ms): GPU timestamps | wall with glFinish around each pass", ""]
    for scene, entry in report["scenes"].items():
        for label, r in entry["configs"].items():
            if "error" in r:
                continue
            gpu, wall = r.get("gpu", {}), r["wall_profiled"]
            passes = list(dict.fromkeys([*gpu, *wall]))
            lines.append(f"**{scene} / {label}**: " + ", ".join(
                f"{p} {_fmt(gpu.get(p))} | {_fmt(wall.get(p))}" for p in passes))
            if "gpu_camera" in r:
                lines.append("camera move, GPU: " + ", ".join(f"{p} {_fmt(v)}" for p, v in r["gpu_camera"].items()))
            lines.append("")
    return "\n".join(lines) + "\n"


# What the GPU machine lacks, fetched here by `prepare` by name from Debian's archive and PyPI: glvnd's
# EGL/GL loaders (the machine has NVIDIA's driver but no loader) and moderngl for its Python 3.12.
GL_DEBS = ("libegl1", "libglvnd0", "libopengl0", "libgl1", "libglx0", "libgles2")
WHEELS = ("moderngl==5.13.0", "glcontext==3.1.0")
WHEEL_PLATFORMS = ("manylinux_2_28_x86_64", "manylinux_2_27_x86_64", "manylinux_2_17_x86_64", "manylinux2014_x86_64",
                   "manylinux1_x86_64")


def prepare() -> None:
    """.gl (the loaders' .deb files), .whl (cp312 wheels) and .gpubench (the scenes), each listed in
    .git/info/exclude so they travel only where `carry` names them (tools/gpu_device.sh)."""
    import subprocess

    exclude = ROOT / ".git" / "info" / "exclude"
    if exclude.parent.is_dir():
        listed = exclude.read_text().split() if exclude.is_file() else []
        with exclude.open("a") as f:
            f.writelines(f"{p}\n" for p in ("/.gl/", "/.whl/", "/.gpubench/") if p not in listed)
    lists = Path("/tmp/bounce-amd64-lists")
    (lists / "partial").mkdir(parents=True, exist_ok=True)
    apt = ["apt-get", "-oAPT::Architecture=amd64", "-oAPT::Architectures=amd64", f"-oDir::State::Lists={lists}"]
    subprocess.run([*apt, "update"], check=True, stdout=subprocess.DEVNULL)
    (ROOT / ".gl").mkdir(exist_ok=True)
    subprocess.run([*apt, "download", *GL_DEBS], check=True, cwd=ROOT / ".gl")
    subprocess.run([sys.executable, "-m", "pip", "download", "-q", "--no-deps", "--only-binary=:all:",
                    "--python-version", "3.12", "--implementation", "cp",
                    *(a for p in WHEEL_PLATFORMS for a in ("--platform", p)), "-d", str(ROOT / ".whl"), *WHEELS],
                   check=True)
    export(ROOT / ".gpubench", list(SCENES))


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    sub = ap.add_subparsers(dest="cmd", required=True)
    sub.add_parser("prepare", help="here, before a GPU run: .gl, .whl and .gpubench for tools/gpu_device.sh")
    ex = sub.add_parser("export", help="capture the scenes (needs bpy)")
    ex.add_argument("--out", type=Path, default=Path(".gpubench"))
    ex.add_argument("--scenes", nargs="*", default=list(SCENES))
    rn = sub.add_parser("run", help="time the methods (needs moderngl and an EGL GL 4.3 context)")
    rn.add_argument("--scenes", type=Path, default=Path(".gpubench"))
    rn.add_argument("--out", type=Path, required=True)
    rn.add_argument("--res", default="1920x1080")
    rn.add_argument("--repeat", type=int, default=20)
    rn.add_argument("--warmup", type=int, default=3)
    rn.add_argument("--only-scenes", nargs="*")
    rn.add_argument("--only-configs", nargs="*")
    md = sub.add_parser("markdown", help="timings.md from a timings.json (a run cut short writes only the json)")
    md.add_argument("json", type=Path)
    rn.add_argument("--budget-s", type=float, help="start no new (scene, config) after this many seconds")
    args = ap.parse_args(argv)
    if args.cmd == "prepare":
        prepare()
        return 0
    if args.cmd == "export":
        export(args.out, args.scenes)
        return 0
    if args.cmd == "markdown":
        print(markdown(json.loads(args.json.read_text())), end="")
        return 0
    w, h = (int(v) for v in args.res.lower().split("x"))
    report = run(args.scenes, args.out, (w, h), args.repeat, args.warmup, args.only_scenes, args.only_configs,
                 args.budget_s)
    print(markdown(report))
    return 0


if __name__ == "__main__":
    sys.exit(main())
