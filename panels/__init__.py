"""Panels: BOUNCE_PT_*, draw only; the logic lives in operators and addon.bridge."""

import bpy

from .main import BOUNCE_PT_main
from .viewport import BOUNCE_PT_viewport_render, BOUNCE_PT_viewport_sidebar

# The parent before its sub-panel.
classes = (BOUNCE_PT_main, BOUNCE_PT_viewport_render, BOUNCE_PT_viewport_sidebar)

# Blender's own helper: registers in order, unregisters in reverse.
register, unregister = bpy.utils.register_classes_factory(classes)
