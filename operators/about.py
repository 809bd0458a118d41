"""BOUNCE_OT_report_renderer: which GPU Bounce runs on, as Blender's gpu module reports it."""

from __future__ import annotations

import bpy
import gpu

from ..addon.bridge.gpu_init import ensure_gpu
from ..addon.engine.errors import BackendUnavailable


class BOUNCE_OT_report_renderer(bpy.types.Operator):
    """Report the GPU renderer Blender draws with (e.g. to tell llvmpipe from a real GPU)"""

    bl_idname = "bounce.report_renderer"
    bl_label = "Report GPU Renderer"

    def execute(self, context):
        # In background mode gpu refuses every call until something initialises it.
        try:
            ensure_gpu()
        except BackendUnavailable as exc:
            self.report({"ERROR"}, str(exc))
            return {"CANCELLED"}
        self.report({"INFO"}, f"{gpu.platform.renderer_get()} ({gpu.platform.backend_type_get()})")
        return {"FINISHED"}
