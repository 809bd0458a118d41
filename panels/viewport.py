"""The overlay's settings, drawn in two places: a sub-panel of Properties > Render > Bounce and the 3D
view's sidebar tab "Bounce" (N panel). Draw only; the status line says what the overlay did last or why
it stopped (the overlay never raises into Blender; the reason is shown here instead)."""

from __future__ import annotations

import bpy


def draw_settings(layout, settings) -> None:
    """Shared by both panels, so the two never drift apart."""
    layout.use_property_split = True
    layout.use_property_decorate = False
    column = layout.column()
    column.active = settings.enabled
    column.prop(settings.gi, "method")
    column.prop(settings, "quality")
    column.prop(settings, "view_mode")
    column.prop(settings, "exposure")
    column.prop(settings, "strength")
    column.prop(settings, "last_update_ms")
    lamps = [ob for ob in bpy.context.scene.objects if ob.type == "LIGHT"]
    if lamps:
        box = layout.box()
        box.label(text="Lights")
        for ob in lamps:
            box.prop(ob.data, "bounce_include", text=ob.name)
    if settings.world_averaged:  # a sky or node-tree world: the overlay never renders it from its timer
        row = layout.row()
        row.label(text="World lit as its average colour", icon="WORLD")
        row.operator("bounce.capture_world", text="Capture", icon="RENDER_STILL")
    status = settings.status
    layout.label(text=status, icon="ERROR" if status.startswith("Error") else "INFO")


class BOUNCE_PT_viewport_render(bpy.types.Panel):
    bl_label = "Viewport Overlay"
    bl_space_type = "PROPERTIES"
    bl_region_type = "WINDOW"
    bl_context = "render"
    bl_parent_id = "BOUNCE_PT_main"

    def draw(self, context):
        draw_settings(self.layout, context.scene.bounce)


class BOUNCE_PT_viewport_sidebar(bpy.types.Panel):
    bl_label = "Bounce"
    bl_space_type = "VIEW_3D"
    bl_region_type = "UI"
    bl_category = "Bounce"

    def draw_header(self, context):
        self.layout.prop(context.scene.bounce, "enabled", text="")

    def draw(self, context):
        draw_settings(self.layout, context.scene.bounce)
