"""The benchmark's anchors besides raw Cycles (ARCHITECTURE.md section 6): Cycles + Open Image Denoise and
EEVEE, each measured against the same Cycles reference in the same run as the methods.

Cycles + OIDN (`denoise_light`, used by bench.cycles_curves on every render of Cycles' curve): Intel Open
Image Denoise (package `pyoidn`, on the CPU), RT filter, HDR, quality high, with the render's Diffuse Color
as albedo and its Normal pass as normal. What is denoised is the light the image shows, pass x Diffuse
Color, not the pass itself: Cycles' Diffuse passes are light divided by Diffuse Color, and OIDN's RT filter
is trained on radiance, whose texture follows the albedo image it is given. The result is divided by the
same Diffuse Color to return to the pass's units (0 where the colour is 0, as Cycles' pass is).
The auxiliary images are marked clean (cleanAux): references point-sample pixel centres (0.01 px filter,
no depth of field or motion blur), so every sample of a pixel sees the same albedo and normal and OIDN
need not prefilter them. Only the indirect product is denoised (OIDN_PRODUCTS).

EEVEE (`render_eevee`): one render per scene at the settings of EEVEE_SETTINGS (see there for why each).

The OIDN part imports without bpy (unit-tested on synthetic images); bpy comes in with render_eevee.
"""

from __future__ import annotations

import statistics
import time

import numpy as np

from ..engine.errors import BackendUnavailable

ANCHORS = ("oidn", "eevee")  # bench --anchors: which anchors run besides raw Cycles
DEFAULT_ANCHORS = ("oidn",)  # EEVEE costs minutes per scene on a CPU rasteriser: asked for, not default
# pyoidn runs numpy images on its CPU device
OIDN_SETTINGS = {"filter": "RT", "hdr": True, "clean_aux": True, "quality": "high"}
OIDN_REPEAT = 3  # timed denoise calls per image after a warm-up; the median is reported
# Diffuse Direct is left raw: it is nearly noise-free at 1 spp, and its spot-cone and shadow edges are in
# neither auxiliary image, so OIDN smears them. On the Cornell box (128 px) it raised the pass's rel_rmse_8
# from 0.017 to 0.040 at 1 spp and from 0.0008 to 0.034 at 64 spp, with or without prefiltering.
OIDN_PRODUCTS = ("indirect",)


def _oidn():
    try:
        import pyoidn
    except ImportError:
        raise BackendUnavailable("Cycles + OIDN needs the pyoidn package (pip install -r requirements.txt)") \
            from None
    return pyoidn


def denoise_light(light_pass: np.ndarray, albedo: np.ndarray, normal: np.ndarray) -> np.ndarray:
    """OIDN-denoised `light_pass` (h, w, >=3; a Cycles Diffuse pass, light / Diffuse Color) in the same
    units, with `albedo` (Diffuse Color) and `normal` (unit normals, 0 on the background) as auxiliary
    images. Only RGB is used and returned (h, w, 3) float32. See the module docstring for why the light is
    multiplied by the albedo before denoising."""
    pyoidn = _oidn()
    albedo = np.ascontiguousarray(np.clip(albedo[:, :, :3], 0.0, 1.0), dtype=np.float32)  # OIDN: albedo in [0, 1]
    normal = np.ascontiguousarray(normal[:, :, :3], dtype=np.float32)
    # negative light is Monte Carlo noise of no physical meaning; OIDN's HDR input must be >= 0
    radiance = np.ascontiguousarray(np.clip(light_pass[:, :, :3], 0.0, None) * albedo, dtype=np.float32)
    out = pyoidn.denoise(radiance, albedo, normal, hdr=OIDN_SETTINGS["hdr"], clean_aux=OIDN_SETTINGS["clean_aux"],
                         quality=OIDN_SETTINGS["quality"], filter_type=OIDN_SETTINGS["filter"])
    return np.where(albedo > 0, out / np.maximum(albedo, np.finfo(np.float32).tiny), 0.0).astype(np.float32)


def timed_denoise(light_pass: np.ndarray, albedo: np.ndarray, normal: np.ndarray) -> tuple[np.ndarray, float]:
    """(denoise_light's image, seconds): the median of OIDN_REPEAT calls after an untimed warm-up call.
    The warm-up takes OIDN's device and filter creation (once per process, as in a renderer that keeps
    its denoiser) out of the time; the time includes the multiply and divide by the albedo."""
    denoise_light(light_pass, albedo, normal)
    times = []
    for _ in range(OIDN_REPEAT):
        t0 = time.perf_counter()
        image = denoise_light(light_pass, albedo, normal)
        times.append(time.perf_counter() - t0)
    return image, statistics.median(times)


# EEVEE (Next, Blender 4.2+) at its best indirect diffuse, chosen by measurement on the Cornell box at
# 128 px against the 512-spp Cycles reference (ARCHITECTURE.md section 6 gives the figures). Ray tracing
# on: without it EEVEE 5.0 gathers no screen-space indirect light at all, Fast GI included. Surfaces
# rougher than trace_max_roughness (0.5, its default), which includes every diffuse one, take the Fast GI
# approximation (horizon scan) in its global illumination mode, here at full resolution; glossy ones
# below it are screen traced at full resolution and denoised. Tracing the diffuse lobe too (max
# roughness 1) lost most of the light (bias 0.22): screen rays that leave the image fall back to light
# probes. A baked volume probe did not help either way (unchanged with tracing, worse with Fast GI) and
# costs a bake whenever a light moves, so there is none. No clamp on indirect light (the default 10
# biases it, as Cycles' would). 64 render samples (the default): Fast GI's bias settled only there.
EEVEE_SETTINGS = {
    "taa_render_samples": 64,
    "use_raytracing": True,
    "ray_tracing_method": "SCREEN",
    "ray_tracing_options.resolution_scale": "1",
    "ray_tracing_options.trace_max_roughness": 0.5,
    "ray_tracing_options.use_denoise": True,
    "use_fast_gi": True,
    "fast_gi_method": "GLOBAL_ILLUMINATION",
    "fast_gi_resolution": "1",
    "clamp_surface_indirect": 0.0,
}
# The same frame without any indirect light: no ray tracing, no Fast GI, and (the scene having no baked
# probe) a world probe that holds the world's own light only. Its Diffuse Light pass is the direct light;
# checked against Cycles' Diffuse Direct on the Cornell box (bias 0.996).
EEVEE_NO_GI = {"use_raytracing": False, "use_fast_gi": False}
EEVEE_LABEL = ("ray tracing: screen trace, full resolution, denoised, max roughness 0.5; Fast GI: global "
               "illumination, full resolution; 64 samples; indirect clamp off")


def _set(eevee, settings: dict) -> None:
    for key, value in settings.items():
        *path, name = key.split(".")
        target = eevee
        for part in path:
            target = getattr(target, part)
        setattr(target, name, value)


def render_eevee(blend, res: int, out_dir) -> dict:
    """EEVEE's indirect diffuse light of `blend` at `res` px (long side) into out_dir/indirect.exr (RGBA,
    A = Combined alpha), in Cycles' Diffuse Indirect units. Returns {time_s: the GI render's call (scene sync,
    shaders not yet compiled and sampling, as reference._render times Cycles), no_gi_time_s, settings,
    settings_label, compared}.

    EEVEE writes no Diffuse Indirect pass: its Diffuse Light pass (the file's "Diffuse Direct") holds direct
    and indirect light together, divided by Diffuse Color as Cycles' passes are. The indirect part is that
    pass at EEVEE_SETTINGS minus the same pass of a render at EEVEE_NO_GI (same samples, so direct light
    and its shadows cancel). The second render only measures; its time is not EEVEE's."""
    from pathlib import Path

    from . import compat, images
    from .capture import image_size
    from .reference import _open_blend, _render

    bpy, scene = _open_blend(blend)
    width, height = image_size(scene, res)
    r = scene.render
    r.engine = "BLENDER_EEVEE"
    r.resolution_x, r.resolution_y, r.resolution_percentage = width, height, 100
    r.use_border = r.use_motion_blur = r.use_compositing = r.use_sequencer = False
    r.film_transparent = True  # Combined alpha = geometry mask, as in the references
    r.filter_size = 0.01  # point-sampled pixel centres, as the references' filter_width
    vl = bpy.context.view_layer
    vl.use_pass_combined = vl.use_pass_diffuse_direct = vl.use_pass_diffuse_color = True
    compat.multilayer_exr(r.image_settings)
    r.image_settings.exr_codec = "NONE"  # read back without OpenImageIO (exr.py), as reference.render_open
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    light, seconds = {}, {}
    # no GI first: the timed GI render then finds the scene's material shaders compiled, as a user's
    # second render would
    for name, settings in (("no_gi", {**EEVEE_SETTINGS, **EEVEE_NO_GI}), ("gi", EEVEE_SETTINGS)):
        _set(scene.eevee, settings)
        exr = out / f"eevee_{name}.exr"
        seconds[name] = _render(bpy, exr)
        light[name] = images.read_multilayer(exr)
    alpha = light["gi"]["Combined"][:, :, 3:4]
    indirect = light["gi"]["Diffuse Direct"][:, :, :3] - light["no_gi"]["Diffuse Direct"][:, :, :3]
    images.write_exr(out / "indirect.exr", np.concatenate([indirect, alpha], axis=2))
    return {"time_s": seconds["gi"], "no_gi_time_s": seconds["no_gi"], "settings": EEVEE_SETTINGS,
            "settings_label": EEVEE_LABEL,
            "compared": "EEVEE's Diffuse Light with GI minus the same without GI, against Diffuse Indirect"}
