"""The panel's verified choice: `--method auto --error-budget E`'s check (pipeline.verify_choice), run on a
copy of the open file in a second Blender process.

Why a second process: the check renders Cycles' Diffuse Indirect pass of the camera (reference.render_open),
which rewrites the scene's render settings, its view layer's passes, the Cycles device preferences and the
Render Result. Done in the user's session it would change what they render next and lose their last render;
in a background Blender on a saved copy it changes nothing of theirs, and the user's Blender stays
responsive while it runs (the operator polls it from a timer, shows its steps and Esc stops it).

The parent (`ChooseJob`, in the user's Blender) writes the copy and the request into a temporary folder and
starts the child: the same Blender binary in background mode with the user's preferences (so the extension
and its wheels load as they do for the user), or, inside the `bpy` module, which has no binary, the same
Python. The child (`child_main`) opens the copy, chooses and checks as `render` does, and writes the result;
each step it prints as a line starting PROGRESS, which the parent shows.
"""

from __future__ import annotations

import json
import shutil
import subprocess
import sys
import tempfile
import traceback
from pathlib import Path

PROGRESS = "bounce-choose: "  # the child's step lines on its stdout, among Blender's own


# -- the child --------------------------------------------------------------------------------------------

def child_main(job_dir: str) -> None:
    """In the second process: job_dir/request.json ({"settings": {group: fields}, "error_budget": E}) ->
    job_dir/result.json ({"ok": True, "decided": decide's dict with the check's verdict} or {"ok": False,
    "error": one line, "traceback": ... for an unexpected failure})."""
    folder = Path(job_dir)
    try:
        decided = _choose_verified(folder / "scene.blend", json.loads((folder / "request.json").read_text()))
        result = {"ok": True, "decided": decided}
    except Exception as exc:  # the parent reports it; the user's session is untouched either way
        from ..engine.errors import BounceError

        result = {"ok": False, "error": str(exc) if isinstance(exc, BounceError) else f"{type(exc).__name__}: {exc}"}
        if not isinstance(exc, BounceError):
            result["traceback"] = traceback.format_exc()
    (folder / "result.json").write_text(json.dumps(result, indent=1))


def _choose_verified(blend: Path, request: dict) -> dict:
    from ..engine import choice
    from ..engine.config import GROUPS
    from ..engine.config import settings as complete_settings
    from . import pipeline

    def progress(step: str) -> None:
        print(PROGRESS + step, flush=True)

    settings = complete_settings(**{group: GROUPS[group].from_dict(fields)
                                    for group, fields in request["settings"].items()})
    progress("opening the copy of the scene")
    captured, (width, height) = pipeline.capture_blend(blend, settings["gi"].resolution)
    budget = request["error_budget"]
    chosen, decided = choice.decide(captured, settings, width * height, error_budget=budget)
    _, decided = pipeline.verify_choice(pipeline.backend(), captured, settings, chosen, decided, budget, progress)
    return {k: v for k, v in decided.items() if k != "features"}


# -- the parent -------------------------------------------------------------------------------------------

class ChooseJob:
    """One check in a second process, started on construction: poll() until done, then result().
    cancel() stops it; close() (always, also after result) removes its folder."""

    def __init__(self, package: str, settings: dict, error_budget: float):
        """package: the extension's package (e.g. bl_ext.user_default.bounce); settings: {group: config}
        as properties.to_config makes them. Raises BounceError where the copy cannot be written."""
        import bpy

        from ..engine.errors import BounceError

        self.folder = Path(tempfile.mkdtemp(prefix="bounce_choose_"))
        try:
            bpy.ops.wm.save_as_mainfile(filepath=str(self.folder / "scene.blend"), copy=True, check_existing=False)
        except RuntimeError as exc:
            self.close()
            raise BounceError(f"cannot save a copy of the scene to check the choice on: {exc}") from None
        (self.folder / "request.json").write_text(json.dumps({
            "settings": {group: config.to_dict() for group, config in settings.items()},
            "error_budget": error_budget}))
        self._out = open(self.folder / "stdout.txt", "wb")
        self._err = open(self.folder / "stderr.txt", "wb")
        self.process = subprocess.Popen(child_command(package, str(self.folder)), stdout=self._out,
                                        stderr=self._err, stdin=subprocess.DEVNULL)

    def poll(self) -> tuple[bool, str]:
        """(whether the child has ended, its last step so far)."""
        text = (self.folder / "stdout.txt").read_text(errors="replace")
        steps = [line[len(PROGRESS):] for line in text.splitlines() if line.startswith(PROGRESS)]
        return self.process.poll() is not None, steps[-1] if steps else "starting Blender"

    def wait(self) -> None:
        self.process.wait()

    def result(self) -> dict:
        """decide's dict with the check's verdict (choice["verified"]); BounceError (one line) when the
        check failed or the child ended without a result."""
        from ..engine.errors import BounceError

        found = self.folder / "result.json"
        if not found.is_file():
            last = (self.folder / "stderr.txt").read_text(errors="replace").strip().splitlines()
            raise BounceError(f"the check's Blender exited with code {self.process.returncode} and no result"
                              + (f": {last[-1]}" if last else ""))
        result = json.loads(found.read_text())
        if not result["ok"]:
            if result.get("traceback"):
                print(result["traceback"], file=sys.stderr)  # for a bug report; the user sees one line
            raise BounceError(f"the check failed: {result['error']}")
        return result["decided"]

    def cancel(self) -> None:
        if self.process.poll() is None:
            self.process.kill()
            self.process.wait()

    def close(self) -> None:
        for stream in (getattr(self, "_out", None), getattr(self, "_err", None)):
            if stream is not None:
                stream.close()
        shutil.rmtree(self.folder, ignore_errors=True)


def child_command(package: str, job_dir: str) -> list[str]:
    """The second process's command line. Blender's binary in background mode, without --factory-startup:
    the user's preferences enable the extension (and put its wheels on the path) as in their session. The
    `bpy` module has no binary (binary_path is empty): its Python, with the package's folder on the path
    (the package is imported by its top-level name there, as the tests import it)."""
    import bpy

    top_level = "." not in package  # its folder's parent must be on the path; bl_ext's Blender sets up
    path_setup = (f"import sys; sys.path.insert(0, {str(Path(sys.modules[package].__file__).parent.parent)!r}); "
                  if top_level else "")
    code = (f"{path_setup}import importlib; "
            f"importlib.import_module({package + '.addon.bridge.choose_job'!r}).child_main({job_dir!r})")
    if bpy.app.binary_path:
        return [bpy.app.binary_path, "--background", "-noaudio", "--python-expr", code]
    return [sys.executable, "-c", code]
