"""Panels: BOUNCE_PT_*, draw only; the logic lives in operators and addon.bridge."""

import bpy

from .main import BOUNCE_PT_main

classes = (BOUNCE_PT_main,)

# Blender's own helper: registers in order, unregisters in reverse.
register, unregister = bpy.utils.register_classes_factory(classes)
