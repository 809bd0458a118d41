"""BOUNCE_OT_bake: bake the selected objects' light with the scene's Bounce settings.

Images: a float image datablock `<object>_bounce_<pass>` per object (packed into the .blend); vertex
colours: a FLOAT_COLOR corner attribute `bounce_<pass>`. Runs on Blender's gpu backend in the UI and on
moderngl in background mode (the same passes on both). Not cancellable: each object is one short GPU job.
"""

from __future__ import annotations

import bpy
from bpy.props import EnumProperty, IntProperty

from ..addon.engine.errors import BounceError

_PASSES = [("indirect", "Indirect", "indirect diffuse light (Cycles' Diffuse Indirect units)"),
           ("direct", "Direct", "direct diffuse light (Cycles' Diffuse Direct units)"),
           ("combined", "Combined", "direct + indirect, without albedo")]
_TARGETS = [("image", "Image", "a float image per object, packed into the .blend"),
            ("vertex-colors", "Vertex Colors", "a colour attribute per mesh corner")]


def _backend():
    """Blender's gpu module inside the UI; moderngl (its own EGL context) in background mode."""
    if bpy.app.background:
        from ..addon.bridge.pipeline import backend
    else:
        from ..addon.bridge.viewport import backend
    return backend()


class BOUNCE_OT_bake(bpy.types.Operator):
    """Bake Bounce's light of the selected mesh objects into images or vertex colours"""

    bl_idname = "bounce.bake"
    bl_label = "Bake Light"
    bl_options = {"REGISTER", "UNDO"}

    size: IntProperty(name="Size", description="lightmap side in texels", default=512, min=8, max=8192)
    pass_name: EnumProperty(name="Pass", items=_PASSES, default="indirect")
    target: EnumProperty(name="Target", items=_TARGETS, default="image")
    margin: IntProperty(name="Margin", description="texels of seam dilation", default=16, min=0, max=1024)

    @classmethod
    def poll(cls, context):
        return context.scene is not None and any(o.type == "MESH" for o in context.selected_objects)

    def invoke(self, context, event):
        return context.window_manager.invoke_props_dialog(self)

    def execute(self, context):
        from ..addon.bridge import bake
        from ..addon.properties import to_config

        objects = sorted((o for o in context.selected_objects), key=lambda o: o.name)
        try:
            gi, rsm = to_config(context.scene.bounce)
            if self.pass_name != "direct" and gi.method == "direct":
                raise BounceError(f"pass {self.pass_name} needs an indirect method: set Bounce > GI > Method to rsm")
            baker = bake.Baker(_backend(), context.evaluated_depsgraph_get(), gi, rsm, self.size)
        except BounceError as exc:
            self.report({"ERROR"}, str(exc))
            return {"CANCELLED"}
        wm = context.window_manager
        progress = not bpy.app.background  # no progress cursor without a window
        if progress:
            wm.progress_begin(0, len(objects))
        done, failed = 0, []
        try:
            for i, obj in enumerate(objects):
                try:
                    if self.target == "image":
                        rgba, notes = baker.bake_image(obj, self.size, self.pass_name, self.margin)
                        bake.store_image(bake.image_name(obj.name, self.pass_name), rgba)
                    else:
                        colors, notes = baker.bake_vertex_colors(obj, self.pass_name)
                        bake.store_vertex_colors(obj.data, bake.attribute_name(self.pass_name), colors)
                    done += 1
                    for note in notes:
                        self.report({"WARNING"}, f"{obj.name}: {note}")
                except BounceError as exc:
                    failed.append(obj.name)
                    self.report({"WARNING"}, f"{obj.name}: {exc}")
                if progress:
                    wm.progress_update(i + 1)
        finally:
            if progress:
                wm.progress_end()
        if done == 0:
            self.report({"ERROR"}, f"nothing baked ({len(failed)} objects failed)")
            return {"CANCELLED"}
        msg = f"baked {done} object(s) ({self.pass_name}, {self.target})"
        self.report({"INFO"}, msg + (f"; failed: {', '.join(failed)}" if failed else ""))
        return {"FINISHED"}
