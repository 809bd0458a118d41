"""Cycles reference renders (ARCHITECTURE.md section 6): the ground truth every method is measured by.

Cycles is configured so that its Diffuse Direct / Indirect / Color passes are an unbiased, per-pixel
(point-sampled) estimate of exactly what a Bounce method computes: `bounces` diffuse bounces and
nothing else, no clamping, no denoising, no adaptive sampling, a 0.01 px pixel filter, and a
transparent film so that Combined alpha is the geometry mask.

Output of render_reference(): out_dir/indirect.exr, direct.exr, albedo.exr, normal.exr, each RGBA float32
with A = Combined alpha (geometry mask; `compare` uses it when the file is the reference), and stats.json.
normal.exr is Cycles' Normal pass (world-space unit normals, 0 on the background): with albedo.exr, the
auxiliary images of the benchmark's Cycles + OIDN anchor (bridge/anchors.py).
With glossy=True also glossy.exr: Glossy Color x Glossy Indirect, the light glossy lobes add to the
image after one glossy bounce (glossy_bounces = 1; its second vertex is lit by `bounces` - 1 diffuse
bounces and direct light), the `vct` method's `glossy` product. Without it glossy_bounces = 0: the
glossy lobes still reflect lights directly (no bounce is needed for that), not other surfaces.
"""

from __future__ import annotations

import json
import tempfile
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np

from ..engine.errors import ConfigError, SceneError
from ..engine.metrics import compare
from . import compat, images
from .capture import image_size, image_unreadable

PASSES = {"indirect": "Diffuse Indirect", "direct": "Diffuse Direct", "albedo": "Diffuse Color", "normal": "Normal"}
GLOSSY_PASSES = ("Glossy Indirect", "Glossy Color")  # multiplied into glossy.exr


SEED_MAX = 2**31 - 1  # Cycles' seed is a signed 32-bit int, at least 0


def check_settings(spp: int, bounces: int, res: int, seed: int = 0) -> None:
    """Raise ConfigError (CLI: exit 2, one line) for values outside what a reference can be."""
    if not 0 <= seed <= SEED_MAX:  # Cycles would clamp it and the stats would name a seed it did not use
        raise ConfigError(f"--seed must be in 0..{SEED_MAX}, got {seed}")
    if spp < 1:
        raise ConfigError(f"--spp must be >= 1, got {spp}")
    if not 1 <= bounces <= 8:
        raise ConfigError(f"--bounces must be in 1..8, got {bounces}")
    if not 8 <= res <= 8192:
        raise ConfigError(f"--res must be in 8..8192, got {res}")


def _open_blend(blend_path):
    import bpy

    p = Path(blend_path)
    if not p.is_file():
        raise SceneError(f"no such file: {blend_path}")
    try:
        bpy.ops.wm.open_mainfile(filepath=str(p), load_ui=False)
    except RuntimeError as exc:  # bpy reports unreadable files as RuntimeError
        raise SceneError(f"cannot open {blend_path}: {str(exc).strip().splitlines()[-1]}") from None
    scene = bpy.context.scene
    if scene.camera is None:
        raise SceneError(f"{blend_path}: the scene has no camera")
    return bpy, scene


def unloadable_images(bpy) -> list[str]:
    """Notes naming each image in use whose file Blender cannot load: Cycles renders it magenta (and the
    capture reads it so, capture.MISSING_IMAGE_RGB), which is rarely the scene its author meant."""
    return [f"image {img.name!r} ({img.filepath}) could not be loaded: Cycles renders it magenta "
            f"(File > External Data > Find Missing Files)"
            for img in bpy.data.images
            if img.users and img.source in ("FILE", "SEQUENCE", "TILED") and image_unreadable(img)]


def _use_gpu_if_any(bpy, scene) -> str:
    """Pick a Cycles GPU device when Cycles reports one, else CPU. Returns a description."""
    scene.cycles.device = "CPU"
    try:
        prefs = bpy.context.preferences.addons["cycles"].preferences
        available = {t[0] for t in prefs.get_device_types(bpy.context)}
        for kind in ("OPTIX", "CUDA", "HIP", "METAL", "ONEAPI"):
            if kind not in available:
                continue
            gpus = [d for d in prefs.get_devices_for_type(kind) if d.type == kind]
            if gpus:
                prefs.compute_device_type = kind
                for d in prefs.get_devices_for_type(kind):
                    d.use = d.type == kind  # GPU only: CPU+GPU mixing changes timings run to run
                scene.cycles.device = "GPU"
                return f"{kind}: " + ", ".join(d.name for d in gpus)
    except (KeyError, AttributeError, TypeError):
        pass  # no cycles preferences (should not happen): CPU is always correct
    return "CPU"


def _configure(bpy, scene, spp, bounces, width, height, seed, exr_path, glossy: bool = False) -> dict:
    r, c = scene.render, scene.cycles
    r.engine = "CYCLES"
    r.resolution_x, r.resolution_y, r.resolution_percentage = width, height, 100
    r.use_border = False
    r.film_transparent = True  # Combined alpha = geometry mask
    r.filter_size = 0.01  # Workbench/EEVEE's filter; Cycles reads cycles.filter_width (set below)
    r.use_motion_blur = False
    r.use_compositing = False  # the passes must come straight from the renderer
    r.use_sequencer = False
    r.use_single_layer = True
    r.use_persistent_data = False
    c.samples = spp
    c.use_adaptive_sampling = False  # adaptive sampling stops early where the estimate looks converged
    c.use_denoising = False
    c.seed, c.use_animated_seed = seed, False
    c.diffuse_bounces = c.max_bounces = bounces
    c.transmission_bounces = c.volume_bounces = c.transparent_max_bounces = 0
    c.glossy_bounces = 1 if glossy else 0
    c.caustics_reflective = c.caustics_refractive = False
    c.sample_clamp_indirect = 0.0  # default 10 clips bright indirect paths: a bias
    c.sample_clamp_direct = 0.0
    c.time_limit = 0.0
    c.filter_width = 0.01  # point-sampled pixel centres, as a G-buffer sees them
    device = _use_gpu_if_any(bpy, scene)
    vl = bpy.context.view_layer
    vl.use_pass_combined = True
    vl.use_pass_diffuse_direct = vl.use_pass_diffuse_indirect = vl.use_pass_diffuse_color = True
    vl.use_pass_normal = True
    vl.use_pass_glossy_indirect = vl.use_pass_glossy_color = glossy
    compat.multilayer_exr(r.image_settings)
    r.image_settings.exr_codec = "NONE"  # read back without OpenImageIO, which a Blender may lack (exr.py)
    r.filepath = str(exr_path)
    r.use_file_extension = False
    settings = {
        k: getattr(c, k)
        for k in (
            "samples", "seed", "diffuse_bounces", "max_bounces", "glossy_bounces", "transmission_bounces",
            "volume_bounces", "transparent_max_bounces", "caustics_reflective", "caustics_refractive",
            "sample_clamp_direct", "sample_clamp_indirect", "filter_width", "use_adaptive_sampling",
            "use_denoising", "use_light_tree", "use_guiding", "pixel_filter_type",
        )
    }
    settings["film_transparent"] = r.film_transparent
    return {"device": device, "cycles": settings}


def _render(bpy, exr_path) -> float:
    """Render and save the multi-layer EXR; returns the render call's wall time in seconds.

    The time covers what a user waits for in Cycles: scene sync, BVH build and sampling (in EEVEE, for
    bench's anchor: scene sync, shaders and sampling). The EXR is written after the timed call
    (Image.save_render), so file I/O is not counted.
    """
    t0 = time.perf_counter()
    bpy.ops.render.render(write_still=False)
    elapsed = time.perf_counter() - t0
    bpy.data.images["Render Result"].save_render(filepath=str(exr_path))
    if not Path(exr_path).is_file():
        raise SceneError(f"{bpy.context.scene.render.engine} wrote no image (render cancelled or failed)")
    return elapsed


def render_open(spp: int, bounces: int, res: int, seed: int, glossy: bool = False,
                progress: Callable[[str], None] = lambda step: None) -> tuple[dict, float, dict]:
    """Cycles on the scene open in this Blender session, configured as the module docstring says (its
    render settings are changed and left so): (the render's layers by pass name, the render call's time
    in s, the device and Cycles settings used)."""
    import bpy

    scene = bpy.context.scene
    width, height = image_size(scene, res)
    with tempfile.TemporaryDirectory(prefix="bounce_ref_") as tmp:
        exr = Path(tmp) / "passes.exr"
        info = _configure(bpy, scene, spp, bounces, width, height, seed, exr, glossy)
        progress(f"Cycles on {info['device']}: {width} x {height} px, {spp} spp")
        render_time = _render(bpy, exr)
        layers = images.read_multilayer(exr)
    missing = [p for p in (*PASSES.values(), "Combined", *(GLOSSY_PASSES if glossy else ())) if p not in layers]
    if missing:
        raise SceneError(f"the render has no {', '.join(missing)} pass (found {sorted(layers)})")
    return layers, render_time, info


def render_reference(blend_path, out_dir, spp: int = 1024, bounces: int = 1, res: int = 256,
                     seed: int = 0, glossy: bool = False, progress: Callable[[str], None] = lambda step: None) -> dict:
    """Render the Cycles reference of `blend_path` into `out_dir` (see module docstring).

    Returns the stats dict also written to out_dir/stats.json; its seed is the one Cycles rendered
    with (read back from Cycles). Raises ConfigError for values out of range and SceneError for a
    missing/unreadable file or a scene without a camera. Opens the file in the running Blender session
    (the current file is replaced). `progress(step)` is told each step.
    """
    check_settings(spp, bounces, res, seed)
    progress(f"opening {blend_path}")
    bpy, scene = _open_blend(blend_path)
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    layers, render_time, info = render_open(spp, bounces, res, seed, glossy, progress)
    width, height = image_size(scene, res)
    alpha = layers["Combined"][:, :, 3:4]
    for name, pass_name in PASSES.items():
        images.write_exr(out / f"{name}.exr", np.concatenate([layers[pass_name][:, :, :3], alpha], axis=2))
    if glossy:
        light = layers[GLOSSY_PASSES[0]][:, :, :3] * layers[GLOSSY_PASSES[1]][:, :, :3]
        images.write_exr(out / "glossy.exr", np.concatenate([light, alpha], axis=2))
    stats = {
        "renderer": "cycles",
        "blend": str(Path(blend_path).resolve()),
        "render_time_s": render_time,
        "spp": spp,
        "bounces": bounces,
        "res": res,
        "width": width,
        "height": height,
        "seed": info["cycles"]["seed"],
        "glossy": glossy,
        "blender_version": bpy.app.version_string,
        **info,
        "notes": unloadable_images(bpy),
    }
    (out / "stats.json").write_text(json.dumps(stats, indent=2))
    return stats


def reference_mask(ref_exr, ref_pixels: np.ndarray, test_exr=None) -> np.ndarray | None:
    """The pixels a reference's light is judged on: its geometry (alpha > 0.5), less the pixels whose
    Diffuse Color is black in the reference (the albedo.exr beside `ref_exr`) or in the image under test
    (the albedo.exr beside `test_exr`, where given). Cycles' Diffuse passes are divided by that colour,
    and a surface without one (an emitter's black panel) has no diffuse light to compare: Cycles writes 0
    there, while Bounce's light products do not depend on it. The test's side matters on an emitter's
    silhouette: Cycles lands a stray sample or two of a pixel beside its centre (docs/DIRECT.md, the
    emissive scene), so a pixel Bounce sees as the black panel can read in Cycles the light of the
    ceiling 2 cm behind it, from 1/spp of its samples. None for a reference without alpha (every pixel
    counts)."""
    if ref_pixels.shape[2] < 4:
        return None
    mask = ref_pixels[:, :, 3] > 0.5
    for light in (ref_exr, test_exr):
        if light is None:
            continue
        albedo = Path(light).with_name("albedo.exr")
        if albedo.name != Path(light).name and albedo.is_file():
            albedo_pixels = images.read_exr(albedo)
            if albedo_pixels.shape[:2] == mask.shape:
                mask &= albedo_pixels[:, :, :3].max(axis=2) > 0
    return mask


def _masked_compare(test_dir, ref_dir, name="indirect") -> dict:
    a = images.read_exr(Path(test_dir) / f"{name}.exr")
    b = images.read_exr(Path(ref_dir) / f"{name}.exr")
    return compare(a[:, :, :3], b[:, :, :3], b[:, :, 3] > 0.5)


def noise_floor(blend, spp: int, bounces: int = 1, res: int = 256, seeds=(0, 1)) -> dict:
    """compare() of two references that differ only in seed: the error the reference itself carries.

    Indirect pass, seeds[1] measured against seeds[0], masked by seeds[0]'s alpha. Extra keys: spp,
    seeds, time_s (the render times). For a reference of N spp, the error of that reference against
    the (unknown) exact image is about this value / sqrt(2).
    """
    with tempfile.TemporaryDirectory(prefix="bounce_noise_") as tmp:
        dirs = [Path(tmp) / f"seed{s}" for s in seeds[:2]]
        times = [render_reference(blend, d, spp, bounces, res, s)["render_time_s"]
                 for d, s in zip(dirs, seeds[:2], strict=True)]
        result = _masked_compare(dirs[1], dirs[0])
    return {**result, "spp": spp, "seeds": list(seeds[:2]), "time_s": times}


def cycles_curve(blend, spp_list, bounces: int, res: int, reference_dir) -> list[dict]:
    """Cycles' error-vs-time curve: one render per spp, measured against reference_dir/indirect.exr.

    The renders use seed = reference seed + 1: with the reference's own seed the first N samples
    would be the reference's first N samples and the error would be under-estimated. The reference
    must have the same bounces and res (checked via its stats.json when present).
    """
    ref = Path(reference_dir)
    if not (ref / "indirect.exr").is_file():
        raise SceneError(f"no reference at {ref}/indirect.exr")
    ref_seed = 0
    if (ref / "stats.json").is_file():
        st = json.loads((ref / "stats.json").read_text())
        ref_seed = int(st.get("seed", 0))
        if st.get("bounces", bounces) != bounces or st.get("res", res) != res:
            raise ConfigError(f"reference {ref} has bounces={st.get('bounces')} res={st.get('res')}, "
                              f"asked for bounces={bounces} res={res}")
    curve = []
    with tempfile.TemporaryDirectory(prefix="bounce_curve_") as tmp:
        for spp in sorted(spp_list):
            d = Path(tmp) / f"spp{spp}"
            stats = render_reference(blend, d, spp, bounces, res, ref_seed + 1)
            m = _masked_compare(d, ref)
            curve.append({"spp": spp, "time_s": stats["render_time_s"], "rel_rmse": m["rel_rmse"],
                          "rel_rmse_8": m["rel_rmse_8"], "bias": m["bias"]})
    return curve


def cycles_bake(obj_name: str, pass_filter: set, spp: int, seed: int, size: int,
                bounces: int = 1) -> tuple[np.ndarray, float]:
    """Cycles' DIFFUSE bake of one object of the open file into a size x size float image, set up as for
    references (`bounces` diffuse bounces, no clamping, denoising or adaptive sampling); pass_filter
    {'INDIRECT'} or {'DIRECT'} without 'COLOR' gives the light alone, in Diffuse Indirect / Direct units.
    Adds an image and an Image Texture node to the object's materials (the bake's target) and leaves the
    render settings so. Returns (rgba, row 0 = top; seconds of the bake call)."""
    import bpy

    scene = bpy.context.scene
    scene.render.engine = "CYCLES"
    c = scene.cycles
    c.device = "CPU"
    c.samples, c.seed = spp, seed
    c.use_adaptive_sampling = c.use_denoising = False
    c.diffuse_bounces = c.max_bounces = bounces
    c.glossy_bounces = c.transmission_bounces = c.volume_bounces = c.transparent_max_bounces = 0
    c.sample_clamp_indirect = c.sample_clamp_direct = 0.0
    obj = bpy.data.objects[obj_name]
    img = bpy.data.images.new(f"cycles_{obj_name}", size, size, alpha=True, float_buffer=True)
    for slot in obj.material_slots:  # the bake writes into the active Image Texture node
        tree = slot.material.node_tree
        node = tree.nodes.get("bake_target") or tree.nodes.new("ShaderNodeTexImage")
        node.name, node.image = "bake_target", img
        tree.nodes.active = node
    for o in scene.objects:
        o.select_set(False)
    obj.select_set(True)
    bpy.context.view_layer.objects.active = obj
    t0 = time.perf_counter()
    bpy.ops.object.bake(type="DIFFUSE", pass_filter=pass_filter, margin=0, use_clear=True, target="IMAGE_TEXTURES")
    seconds = time.perf_counter() - t0
    px = np.empty(size * size * 4, np.float32)
    img.pixels.foreach_get(px)
    return px.reshape(size, size, 4)[::-1].copy(), seconds
