"""BOUNCE_OT_capture_world: render the scene's world into its map of light by direction, so the viewport
overlay lights with a sky or any node tree by direction instead of its average colour."""

from __future__ import annotations

import time

import bpy

from ..addon.bridge import live, world_capture


class BOUNCE_OT_capture_world(bpy.types.Operator):
    """Render the world's light by direction with Cycles (about a second) for the viewport overlay, which
    otherwise lights a sky or node-tree world as its average colour; kept in the world (saved with the
    file) until the world changes"""

    bl_idname = "bounce.capture_world"
    bl_label = "Capture World Light"
    # It writes the map into the world's custom properties (world_capture.store: saved with the .blend),
    # so undo takes it back. The render is of a temporary scene: the Render Result still shows the
    # user's last render of theirs.
    bl_options = {"REGISTER", "UNDO"}

    @classmethod
    def poll(cls, context):
        return context.scene is not None and world_capture.needs_map(context.scene.world)

    def execute(self, context):
        world = context.scene.world
        start = time.perf_counter()
        try:
            world_capture.store(world, world_capture.capture(world))
        except RuntimeError as exc:  # Cycles refused to render (no Cycles in this build, say)
            self.report({"ERROR"}, f"Bounce: cannot render the world {world.name!r}: {exc}")
            return {"CANCELLED"}
        live.touch()  # the overlay re-captures and now finds the map
        self.report({"INFO"}, f"Bounce: world {world.name!r} captured by direction in "
                              f"{time.perf_counter() - start:.1f} s")
        return {"FINISHED"}
