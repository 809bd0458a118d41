"""Panels: BOUNCE_PT_*, draw only; the logic lives in operators and addon.bridge."""

import bpy

from .main import BOUNCE_PT_main

classes = (BOUNCE_PT_main,)


def register():
    for cls in classes:
        bpy.utils.register_class(cls)


def unregister():
    for cls in reversed(classes):
        bpy.utils.unregister_class(cls)
