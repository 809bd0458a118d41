"""BOUNCE_OT_bake: bake the selected objects' light with the scene's Bounce settings.

Images: a float image datablock `<object>_bounce_<pass>` per object (packed into the .blend); vertex
colours: a FLOAT_COLOR corner attribute `bounce_<pass>`. Runs on Blender's gpu backend in the UI and on
moderngl in background mode (the same passes on both). In a window the bake is modal: one object per
timer tick, a progress bar, and Esc cancels (objects already baked are kept, the rest are not started).
In background mode (scripts, `blender --background`) it runs to the end in `execute`.
"""

from __future__ import annotations

import bpy
from bpy.props import EnumProperty, IntProperty

from ..addon.engine import registry
from ..addon.engine.errors import BounceError
from ..addon.engine.lightmap import SUPERSAMPLE_MAX, check_supersample

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
    supersample: IntProperty(name="Supersample", description="sub-texels per texel side (images): each texel the "
                             "mean light over its footprint, as Cycles' bake; N x N times the work", default=1,
                             min=1, max=SUPERSAMPLE_MAX)

    @classmethod
    def poll(cls, context):
        return context.scene is not None and any(o.type == "MESH" for o in context.selected_objects)

    def invoke(self, context, event):
        return context.window_manager.invoke_props_dialog(self)

    def execute(self, context):
        if not self._start(context):
            return {"CANCELLED"}
        if bpy.app.background or context.window is None:
            for obj in self._objects:
                self._bake(obj)
            return self._finish()
        wm = context.window_manager
        wm.progress_begin(0, len(self._objects))
        self._timer = wm.event_timer_add(0.01, window=context.window)
        wm.modal_handler_add(self)
        return {"RUNNING_MODAL"}

    def modal(self, context, event):
        if event.type == "ESC":
            self._stop(context)
            self.report({"WARNING"}, f"bake cancelled after {self._done} of {len(self._objects)} object(s)")
            return {"CANCELLED"}
        if event.type != "TIMER":
            return {"PASS_THROUGH"}
        self._bake(self._objects[self._next])
        self._next += 1
        context.window_manager.progress_update(self._next)
        if self._next < len(self._objects):
            return {"RUNNING_MODAL"}
        self._stop(context)
        return self._finish()

    def _start(self, context) -> bool:
        """Capture and upload the scene once; False (with a report) when it cannot bake."""
        from ..addon.bridge import bake
        from ..addon.properties import to_config

        self._objects = sorted((o for o in context.selected_objects), key=lambda o: o.name)
        self._next, self._done, self._failed = 0, 0, []
        try:
            settings = to_config(context.scene.bounce)
            method = settings["gi"].method
            if self.pass_name != "direct" and "indirect" not in registry.get(method).products:
                raise BounceError(f"pass {self.pass_name} needs an indirect method: set Bounce > GI > Method to rsm")
            if self.target == "image":
                check_supersample(self.supersample, self.size)
            self._baker = bake.Baker(_backend(), context.evaluated_depsgraph_get(), settings, self.size)
        except BounceError as exc:
            self.report({"ERROR"}, str(exc))
            return False
        # A scene without light bakes black images: say so once (the bake still runs, as asked).
        self._unlit = bake.empty_light_warning(self._baker.scene)
        if self._unlit:
            self.report({"WARNING"}, self._unlit)
        return True

    def _bake(self, obj) -> None:
        """One object into its image or colour attribute; a failure is reported and the others go on."""
        from ..addon.bridge import bake

        try:
            if self.target == "image":
                values, notes = self._baker.bake_image(obj, self.size, self.pass_name, self.margin, self.supersample)
                bake.store_image(bake.image_name(obj.name, self.pass_name), values)
            else:
                values, notes = self._baker.bake_vertex_colors(obj, self.pass_name)
                bake.store_vertex_colors(obj.data, bake.attribute_name(self.pass_name), values)
            dark = None if self._unlit else bake.zero_light_warning(values)  # the scene's warning says it
            notes = notes + [dark] if dark else notes
            self._done += 1
            for note in notes:
                self.report({"WARNING"}, f"{obj.name}: {note}")
        except BounceError as exc:
            self._failed.append(obj.name)
            self.report({"WARNING"}, f"{obj.name}: {exc}")

    def _stop(self, context) -> None:
        wm = context.window_manager
        wm.event_timer_remove(self._timer)
        wm.progress_end()

    def _finish(self):
        if self._done == 0:
            self.report({"ERROR"}, f"nothing baked ({len(self._failed)} objects failed)")
            return {"CANCELLED"}
        msg = f"baked {self._done} object(s) ({self.pass_name}, {self.target})"
        self.report({"INFO"}, msg + (f"; failed: {', '.join(self._failed)}" if self._failed else ""))
        return {"FINISHED"}
