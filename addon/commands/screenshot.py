"""`python -m addon screenshot --out DIR`: the viewport overlay on the Cornell box, rendered headless.

Writes `viewport.png` (what Blender's Solid view shows: a Workbench render from the scene camera) and
`viewport_bounce.png` (the same with Bounce's overlay added, by the overlay's own draw callback into an
offscreen buffer with the camera's view and projection matrices), plus `overlay.exr` (what the overlay
added, linear). No window is needed: this is how the README's screenshot is made.
"""

from __future__ import annotations

import types
from pathlib import Path

import numpy as np

from ..engine.config import GIConfig
from ..engine.errors import ConfigError
from ._args import output_dir
from ._settings import add_field_flag

NAME = "screenshot"
HELP = "render the Cornell box with and without the viewport overlay (headless) into PNGs"
# The overlay's view modes: bridge/viewport.py's MODE_WEIGHTS keys, restated because that module imports
# Blender's gpu module and the arguments are checked before Blender loads (a test keeps them equal).
VIEWS = ("COMBINED", "INDIRECT", "DIRECT", "VOXELS")


def add_arguments(p) -> None:
    p.add_argument("--out", default="docs/images", help="output directory")
    add_field_flag(p, GIConfig, "resolution", "--res", default=320, doc="image side in pixels")
    add_field_flag(p, GIConfig, "method", doc="overlay method")
    p.add_argument("--view", default="INDIRECT", choices=VIEWS, metavar="{" + ",".join(VIEWS) + "}",
                   help="overlay view mode (default: INDIRECT); VOXELS: the method's voxel grid (rsm)")


def _check_view(view: str, method: str) -> None:
    """VOXELS shows a voxel grid: refuse a method without one before anything is drawn."""
    from ..engine import methods
    from ..engine.config import METHODS

    if view == "VOXELS" and not hasattr(methods.get(method), "voxel_view"):
        gridded = ", ".join(m for m in METHODS if hasattr(methods.get(m), "voxel_view"))
        raise ConfigError(f"--view VOXELS shows a method's voxel grid: --method {method} has none (use {gridded})")


def _srgb(linear: np.ndarray) -> np.ndarray:
    c = np.clip(linear, 0.0, 1.0)
    return np.where(c <= 0.0031308, 12.92 * c, 1.055 * np.power(c, 1 / 2.4) - 0.055)


def _linear(srgb: np.ndarray) -> np.ndarray:
    return np.where(srgb <= 0.04045, srgb / 12.92, ((srgb + 0.055) / 1.055) ** 2.4)


def _workbench(bpy, path: Path, size: int) -> np.ndarray:
    """Solid-view look: a Workbench render (studio light, material colours), linear RGB, row 0 = top."""
    import matplotlib.pyplot as plt

    scene = bpy.context.scene
    scene.render.engine = "BLENDER_WORKBENCH"
    scene.display.shading.color_type = "MATERIAL"
    scene.render.resolution_x = scene.render.resolution_y = size
    scene.render.resolution_percentage = 100
    scene.render.filepath = str(path)
    scene.render.image_settings.file_format = "PNG"
    bpy.ops.render.render(write_still=True)
    return _linear(plt.imread(path)[..., :3].astype(np.float64))


def run(args) -> int:
    _check_view(args.view, args.method)
    out = output_dir(args.out)
    import bpy
    import gpu
    import matplotlib.pyplot as plt

    from ..bridge import images, live, scenes, viewport
    from ..properties import register as register_properties
    from ..properties import unregister as unregister_properties

    scenes.build("cornell")
    base = _workbench(bpy, out / "viewport.png", args.res)
    register_properties()
    try:
        settings = bpy.context.scene.bounce
        settings.gi.method, settings.gi.resolution = args.method, args.res
        settings.view_mode, settings.enabled = args.view, True
        live.capture(bpy.context.evaluated_depsgraph_get())
        cam = bpy.context.scene.camera
        region_data = types.SimpleNamespace(
            view_matrix=cam.matrix_world.inverted(),
            window_matrix=cam.calc_matrix_camera(bpy.context.evaluated_depsgraph_get(), x=args.res, y=args.res))
        region = types.SimpleNamespace(width=args.res, height=args.res, as_pointer=lambda: 0)
        context = types.SimpleNamespace(scene=bpy.context.scene, region=region, region_data=region_data)
        viewport.backend()  # initialises Blender's gpu module in background mode
        offscreen = gpu.types.GPUOffScreen(args.res, args.res, format="RGBA32F")
        try:
            with offscreen.bind():
                fb = gpu.state.active_framebuffer_get()
                fb.clear(color=(0.0, 0.0, 0.0, 0.0))
                viewport.draw_callback(context)
                added = np.array(fb.read_color(0, 0, args.res, args.res, 4, 0, "FLOAT").to_list(), np.float32)
        finally:
            offscreen.free()
        if live.STATE.error:
            raise RuntimeError(live.STATE.error)
    finally:
        unregister_properties()
    added = added[::-1, :, :3]  # GL row 0 is the bottom
    images.write_exr(out / "overlay.exr", np.ascontiguousarray(added))
    plt.imsave(out / "viewport_bounce.png", _srgb(base + added))
    print(f"wrote {out}/viewport.png and {out}/viewport_bounce.png")
    return 0
