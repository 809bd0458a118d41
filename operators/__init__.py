"""Operators: BOUNCE_OT_*, one per file, thin (gather config, call bridge/engine, report)."""

import bpy

from .about import BOUNCE_OT_report_renderer
from .bake import BOUNCE_OT_bake
from .capture_world import BOUNCE_OT_capture_world
from .choose import BOUNCE_OT_choose

classes = (BOUNCE_OT_report_renderer, BOUNCE_OT_bake, BOUNCE_OT_choose, BOUNCE_OT_capture_world)

# Blender's own helper: registers in order, unregisters in reverse.
register, unregister = bpy.utils.register_classes_factory(classes)
