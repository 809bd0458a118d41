"""BOUNCE_PT_main: Properties > Render > Bounce. Draws scene.bounce; no logic."""

from __future__ import annotations

import bpy

from ..addon.engine import choice, registry
from ..addon.engine.errors import BounceError
from ..addon.properties import CONFIGS, to_config

_model = []  # the choice model, loaded on the first draw that needs it


def _still_chosen(settings) -> bool:
    """Whether the settings are still the row Choose for Budget set (else its note no longer holds)."""
    try:
        if not _model:
            _model.append(choice.load())
        return choice.row_for(_model[0], to_config(settings)) == settings.choice_row
    except BounceError:
        return False


class BOUNCE_PT_main(bpy.types.Panel):
    bl_label = "Bounce"
    bl_space_type = "PROPERTIES"
    bl_region_type = "WINDOW"
    bl_context = "render"

    def draw_header(self, context):
        self.layout.prop(context.scene.bounce, "enabled", text="")

    def draw(self, context):
        layout = self.layout
        layout.use_property_split = True
        layout.use_property_decorate = False
        settings = context.scene.bounce
        # Greyed while the overlay is off, but still editable: bakes read the same settings, and a bake
        # does not need the overlay.
        settings_column = layout.column()
        settings_column.active = settings.enabled
        # The fields the chosen method reads (the registry's `reads`), in each config's order: a new
        # config field appears without edits here, under the methods that read it.
        method = registry.get(settings.gi.method)
        for attr in CONFIGS:
            group = getattr(settings, attr)
            names = [n for n in group.bl_rna.properties.keys()
                     if n not in {"rna_type", "name"} and method.reads_setting(attr, n)]
            if names:
                column = settings_column.column(heading=attr.upper())
                for name in names:
                    column.prop(group, name)
        # Choosing serves bakes too: never greyed with the overlay.
        row = layout.row(align=True)
        row.prop(settings, "error_budget")
        row.operator("bounce.choose", text="", icon="AUTO")
        if settings.choice_note and _still_chosen(settings):
            layout.label(text=settings.choice_note, icon="INFO")
        layout.operator("bounce.report_renderer", icon="INFO")
        box = layout.box()
        box.label(text="Bake (selected objects)", icon="RENDER_STILL")
        box.operator("bounce.bake", icon="TEXTURE")
