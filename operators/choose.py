"""BOUNCE_OT_choose: set the scene's method and its settings to the fastest the choice finds within the
scene's error budget (addon/engine/choice.py), checked as `render --method auto --error-budget E` checks
it, and note the error expected.

The check (choice.verify: the model's candidates rendered and judged by a few-sample Cycles render of the
camera) runs in a second Blender on a copy of the file (addon/bridge/choose_job.py says why): from the
panel it is modal, with the step in the status bar, and Esc stops it with nothing changed; from a script
(execute) it runs to the end. Held out over the benchmark scenes the checked choice met the budget on
12, 12 and 15 of 15 scenes at E = 0.1, 0.2 and 0.3, the model's alone on 9, 9 and 12
(benchmarks/choice/REPORT.md): so the panel checks by default, and Verify off takes the model's choice
at once."""

from __future__ import annotations

import bpy
from bpy.props import BoolProperty

from ..addon.bridge.capture import SceneCache, image_size
from ..addon.engine import choice
from ..addon.engine.errors import BounceError
from ..addon.properties import set_from_config, to_config

PACKAGE = __package__.rsplit(".", 1)[0]  # the extension's package: the check's Blender imports it by this


def note(decided: dict) -> str:
    """The panel's line: the chosen setting, its expected error in per cent of a path tracer's light, and
    whether a Cycles check on this scene or the model alone gave that figure."""
    c = decided["choice"]
    setting = ", ".join(f"{k.split('.')[-1]} {v}" for k, v in c["setting"].items()) or "its defaults"
    checked = decided.get("estimate_source") == "path-traced check"
    return (f"{c['method']} ({setting}): ~{100 * decided['estimated_rel_rmse_8']:.0f} % from a path tracer"
            + (", checked by Cycles" if checked else ", the model's estimate")
            + ("" if c["meets_budget"] else " (over the budget: the most accurate found)"))


class BOUNCE_OT_choose(bpy.types.Operator):
    """Choose the method and settings fastest within the error budget for this scene, checked against a
    short Cycles render of the camera"""

    bl_idname = "bounce.choose"
    bl_label = "Choose for Budget"
    bl_options = {"REGISTER", "UNDO"}

    verify: BoolProperty(name="Verify", default=True,
                         description="check the model's candidates against a short Cycles render of the camera "
                         "in a second Blender (seconds to a minute); off: the model's choice at once, unchecked")

    def execute(self, context):
        job = self._start(context)
        if job is None:
            return {"FINISHED"} if self._applied else {"CANCELLED"}
        try:
            job.wait()
            return self._finish(context, job)
        finally:
            job.close()

    def invoke(self, context, event):
        if bpy.app.background or context.window is None:
            return self.execute(context)
        self._job = self._start(context)
        if self._job is None:
            return {"FINISHED"} if self._applied else {"CANCELLED"}
        wm = context.window_manager
        self._timer = wm.event_timer_add(0.25, window=context.window)
        wm.modal_handler_add(self)
        context.workspace.status_text_set("Bounce: checking the choice (Esc stops): starting Blender")
        return {"RUNNING_MODAL"}

    def modal(self, context, event):
        if event.type == "ESC":
            self._stop(context)
            self.report({"WARNING"}, "Bounce: the check was stopped; the settings are unchanged")
            return {"CANCELLED"}
        if event.type != "TIMER":
            return {"PASS_THROUGH"}
        done, step = self._job.poll()
        if not done:
            context.workspace.status_text_set(f"Bounce: checking the choice (Esc stops): {step}")
            return {"RUNNING_MODAL"}
        try:
            return self._finish(context, self._job)
        finally:
            self._stop(context)

    def cancel(self, context):
        """Blender ends the modal run (a file loaded, the window closed): the check's process and folder
        must not outlive it."""
        self._stop(context)

    def _start(self, context):
        """The model's choice, applied at once where it is not to be checked (Verify off, or no camera to
        check it with); else the started check (a ChooseJob). None when nothing is left to run."""
        from ..addon.bridge.choose_job import ChooseJob

        scene, settings = context.scene, context.scene.bounce
        self._applied = False
        try:
            configs = to_config(settings)
            if self.verify and scene.camera is not None:
                return ChooseJob(PACKAGE, configs, settings.error_budget)
            width, height = image_size(scene, configs["gi"].resolution)
            captured = SceneCache().update(context.evaluated_depsgraph_get(), width, height)
            _, decided = choice.decide(captured, configs, width * height, error_budget=settings.error_budget)
        except BounceError as exc:
            self.report({"ERROR"}, str(exc))
            return None
        self._apply(settings, configs, decided)
        unchecked = " (not checked: the scene has no camera for Cycles to render)" if self.verify else ""
        self.report({"WARNING" if unchecked else "INFO"},
                    f"Bounce: {settings.choice_note}; {decided['choice']['why']}{unchecked}")
        return None

    def _finish(self, context, job) -> set[str]:
        settings = context.scene.bounce
        try:
            decided = job.result()
            self._apply(settings, to_config(settings), decided)
        except BounceError as exc:
            self.report({"ERROR"}, f"Bounce: {exc}; the settings are unchanged")
            return {"CANCELLED"}
        self.report({"INFO"}, f"Bounce: {settings.choice_note}; {decided['choice']['why']}")
        return {"FINISHED"}

    def _apply(self, settings, configs: dict, decided: dict) -> None:
        c = decided["choice"]
        set_from_config(settings, choice.apply_row(configs, c["method"], c["setting"]))
        settings.choice_row = c["row"]
        settings.choice_note = note(decided)
        self._applied = True

    def _stop(self, context) -> None:
        context.window_manager.event_timer_remove(self._timer)
        if context.workspace is not None:  # none while a file loads
            context.workspace.status_text_set(None)
        self._job.cancel()
        self._job.close()
