"""BOUNCE_OT_choose: set the scene's method and its settings to the ones the choice model expects to be
fastest within the scene's error budget (addon/engine/choice.py), and note the expected error."""

from __future__ import annotations

import bpy

from ..addon.bridge.capture import SceneCache, image_size
from ..addon.engine import choice
from ..addon.engine.errors import BounceError
from ..addon.properties import set_from_config, to_config


def note(decided: dict) -> str:
    """The panel's line: the chosen setting, its expected error in per cent of a path tracer's light."""
    c = decided["choice"]
    setting = ", ".join(f"{k.split('.')[-1]} {v}" for k, v in c["setting"].items())
    return (f"{c['method']} ({setting}): ~{100 * decided['estimated_rel_rmse_8']:.0f} % from a path tracer"
            + ("" if c["meets_budget"] else " (over the budget: the most accurate known)"))


class BOUNCE_OT_choose(bpy.types.Operator):
    """Choose the method and settings expected to be fastest within the error budget for this scene"""

    bl_idname = "bounce.choose"
    bl_label = "Choose for Budget"
    bl_options = {"REGISTER", "UNDO"}

    def execute(self, context):
        scene = context.scene
        settings = scene.bounce
        try:
            configs = to_config(settings)
            width, height = image_size(scene, configs["gi"].resolution)
            captured = SceneCache().update(context.evaluated_depsgraph_get(), width, height)
            chosen, decided = choice.decide(captured, configs, width * height, error_budget=settings.error_budget)
        except BounceError as exc:
            self.report({"ERROR"}, str(exc))
            return {"CANCELLED"}
        set_from_config(settings, chosen)
        settings.choice_row = decided["choice"]["row"]
        settings.choice_note = note(decided)
        self.report({"INFO"}, f"Bounce: {settings.choice_note}; {decided['choice']['why']}")
        return {"FINISHED"}
