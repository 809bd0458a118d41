"""Makes Blender's `gpu` module usable in background mode (`blender --background`, the bpy module).

Right after `import bpy` in background mode, GPU calls are refused. Blender 5.2+ offers `gpu.init()`;
on 5.0/5.1 the only way is a GPU render, so we render 8x8 pixels with Workbench in a throwaway scene
(~1 s on llvmpipe), leaving the user's scenes untouched.
"""

from __future__ import annotations

import bpy
import gpu

from ..engine.errors import BackendUnavailable

_ready = False


def ensure_gpu() -> None:
    global _ready
    if _ready:
        return
    if _gpu_usable():
        _ready = True
        return
    if hasattr(gpu, "init"):
        gpu.init()
    else:
        _render_workbench_once()
    if not _gpu_usable():
        raise BackendUnavailable("Blender's gpu module stays unavailable after initialisation")
    _ready = True


def _gpu_usable() -> bool:
    try:
        gpu.types.GPUOffScreen(1, 1).free()
    except (SystemError, RuntimeError, ValueError):
        return False
    return True


def _render_workbench_once() -> None:
    scene = bpy.data.scenes.new("bounce_gpu_init")
    cam_data = bpy.data.cameras.new("bounce_gpu_init")
    cam = bpy.data.objects.new("bounce_gpu_init", cam_data)
    try:
        scene.collection.objects.link(cam)
        scene.camera = cam
        scene.render.engine = "BLENDER_WORKBENCH"
        scene.render.resolution_x = scene.render.resolution_y = 8
        scene.render.resolution_percentage = 100
        bpy.ops.render.render(scene=scene.name)
    finally:
        bpy.data.scenes.remove(scene)
        bpy.data.objects.remove(cam)
        bpy.data.cameras.remove(cam_data)
