"""Operators: BOUNCE_OT_*, one per file, thin (gather config, call bridge/engine, report)."""

import bpy

from .about import BOUNCE_OT_report_renderer

classes = (BOUNCE_OT_report_renderer,)


def register():
    for cls in classes:
        bpy.utils.register_class(cls)


def unregister():
    for cls in reversed(classes):
        bpy.utils.unregister_class(cls)
