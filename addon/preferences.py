"""Add-on preferences. Blender finds them by bl_idname == the add-on's module name, which is
`bl_ext.<repo>.bounce` when installed as an extension and something else in tests, so it is computed."""

from __future__ import annotations

import bpy
from bpy.props import EnumProperty, IntProperty

ADDON_PACKAGE = __package__.rpartition(".")[0]  # this module lives in <package>.addon


class BOUNCE_AP_preferences(bpy.types.AddonPreferences):
    bl_idname = ADDON_PACKAGE

    backend: EnumProperty(
        name="Backend",
        description="GPU backend the viewport and bakes run on",
        items=[
            ("BLENDER", "Blender GPU", "Blender's gpu module: works on OpenGL, Vulkan and Metal"),
            # moderngl must never touch Blender's own context, which it cannot share on Vulkan or Metal.
            ("MODERNGL", "ModernGL (tests)", "A standalone OpenGL context; for tests and comparisons only"),
        ],
        default="BLENDER",
    )
    memory_budget_mb: IntProperty(
        name="GPU Memory Budget (MB)",
        description="Upper bound for Bounce's textures and volumes; resolutions are lowered to fit",
        default=1024,
        min=64,
        max=16384,
    )

    def draw(self, context):
        layout = self.layout
        layout.prop(self, "backend")
        layout.prop(self, "memory_budget_mb")


def register() -> None:
    bpy.utils.register_class(BOUNCE_AP_preferences)


def unregister() -> None:
    bpy.utils.unregister_class(BOUNCE_AP_preferences)
