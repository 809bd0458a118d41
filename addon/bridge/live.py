"""Live updates: depsgraph changes -> a captured Scene the viewport overlay renders from.

Why it is shaped like this:
- `depsgraph.updates` is only filled inside `depsgraph_update_post`, so the handler only *notes* what
  changed (`SceneCache.note`, cheap) and schedules one timer; the timer captures. A burst of updates
  (dragging a light sends one per mouse move) thus costs one capture, and never more than one is in
  flight: the handler registers the timer only when it is not registered already.
- What changed is decided by comparing the new capture with the previous one, not by classifying
  `depsgraph.updates`: those also arrive for settings edits, and a moved mesh, a new material colour or
  a deleted object all show up differently. Geometry (positions, normals, albedo, emission, glossy lobe) bumps
  `geometry_version` (the overlay re-uploads); lights or the world bump `lights_version` (the overlay
  re-runs the light passes only). The cache re-reads no mesh for a light change (`geometry_reads`).
- The timer does no GPU work: a GPU context is only certain inside a draw callback (on every Blender
  GPU backend), so the overlay computes there, from the versions recorded here.
- Quality: while updates keep arriving (less than IDLE_S apart) the state says "preview" (the overlay
  uses half resolution and a quarter of the VPLs) and the timer comes back every IDLE_S; once idle it
  says "full" and stops.
- Nothing here writes to Blender data: writing from a draw callback is refused, and every write would
  send another depsgraph update. The panel reads `STATE` through read-only properties.
- The world: an HDRI lights by direction (read in milliseconds); a world Bounce cannot read (a Sky
  Texture, any node tree) is never rendered from the timer and lights as its average until the
  Capture World Light operator renders its map (`world_averaged` says so to the panel); the map is
  part of the lights' comparison, so turning the sky's sun is a lights change.
"""

from __future__ import annotations

import dataclasses
import itertools
import logging
import math
import time

import bpy
import numpy as np

from ..engine.scene import Scene
from . import world_capture
from .capture import SceneCache

log = logging.getLogger(__name__)

DELAY_S = 0.02  # first capture after an update: lets the rest of a burst arrive
IDLE_S = 0.1    # updates closer than this are one interaction: preview quality until it ends

_versions = itertools.count(1)  # never reset, so an overlay can never mistake a new file for its old one


@dataclasses.dataclass
class LiveState:
    # No Cycles render of the world from the UI's timer (module docstring, "The world").
    cache: SceneCache = dataclasses.field(default_factory=lambda: SceneCache(render_world=False))
    scene_name: str | None = None
    scene: Scene | None = None      # the last capture (its camera is replaced by each region's)
    geometry_version: int = 0
    lights_version: int = 0
    quality: str = "full"           # "preview" while updates keep arriving, "full" when idle
    last_event_s: float = -math.inf
    captures: int = 0
    changed: tuple[str, ...] = ()   # what the last capture changed: "geometry", "lights"
    world_averaged: bool = False    # the world varies with direction but lights as its average (no map yet)
    # Written by the viewport overlay, read by the panel.
    last_update_ms: float = 0.0
    info: str = ""
    samples: int = 0                # gathers the overlay has averaged since the last change
    note: str | None = None         # the overlay shows something other than what was asked, and why
    error: str | None = None


STATE = LiveState()


# ------------------------------------------------------------------------------------------------ errors

def fail(where: str, exc: BaseException) -> None:
    """Stop the live overlay after an error: log it once with its traceback, keep the reason for the
    panel. Nothing runs again until `reset()` (toggling Enabled)."""
    if STATE.error is None:
        log.error("Bounce %s failed; the overlay is off until re-enabled", where, exc_info=exc)
        STATE.error = f"{where}: {type(exc).__name__}: {exc}"


def status() -> str:
    """One line for the panel."""
    if STATE.error:
        return f"Error: {STATE.error}"
    if STATE.scene is None:
        return "Waiting for the first update"
    warnings = f", {len(STATE.scene.warnings)} capture warning(s)" if STATE.scene.warnings else ""
    note = f"; {STATE.note}" if STATE.note else ""
    return f"{STATE.info or 'captured'}{warnings}{note}"


# ---------------------------------------------------------------------------------------------- capture

def _same_arrays(a: tuple, b: tuple) -> bool:
    return all(x.shape == y.shape and np.array_equal(x, y) for x, y in zip(a, b, strict=True))


def _geometry(scene: Scene) -> tuple:
    return (scene.positions_m, scene.normals, scene.albedo, scene.bounce_reflectance(), scene.emission,
            scene.specular_f0(), scene.glossy_roughness())


def _lights(scene: Scene) -> list:
    rows = [[np.asarray(v).tolist() if isinstance(v, np.ndarray) else v for v in dataclasses.astuple(light)]
            for light in scene.lights]
    world = None if scene.world_map is None else scene.world_map.tobytes()
    return [rows, scene.world_color.tolist(), world]


def capture(depsgraph) -> tuple[str, ...]:
    """Capture the depsgraph's scene; bump the versions of what differs from the last capture."""
    if depsgraph.scene.name != STATE.scene_name:
        STATE.cache, STATE.scene, STATE.scene_name = SceneCache(render_world=False), None, depsgraph.scene.name
    previous = STATE.scene
    # 1 x 1: the scene camera is not what the viewport shows; each region builds its own camera.
    scene = STATE.cache.update(depsgraph, 1, 1)
    STATE.captures += 1
    changed = []
    if previous is None or not _same_arrays(_geometry(previous), _geometry(scene)):
        STATE.geometry_version = next(_versions)
        changed.append("geometry")
    if previous is None or _lights(previous) != _lights(scene):
        STATE.lights_version = next(_versions)
        changed.append("lights")
    STATE.scene, STATE.changed = scene, tuple(changed)
    STATE.world_averaged = scene.world_map is None and world_capture.needs_map(depsgraph.scene.world)
    return STATE.changed


# ------------------------------------------------------------------------------------ handler and timer

def _enabled(scene) -> bool:
    settings = getattr(scene, "bounce", None)
    return settings is not None and settings.enabled and STATE.error is None


def touch() -> None:
    """Something changed (an update, a view moved): preview quality until IDLE_S passes, then full."""
    STATE.last_event_s = time.perf_counter()
    request()


def request() -> None:
    """Schedule a capture, unless one is already scheduled (the coalescing)."""
    if not bpy.app.timers.is_registered(tick):
        bpy.app.timers.register(tick, first_interval=DELAY_S)


@bpy.app.handlers.persistent
def on_depsgraph_update(scene, depsgraph) -> None:
    if not _enabled(scene):
        return
    try:
        STATE.cache.note(depsgraph)  # only here are depsgraph.updates filled
        touch()
    except Exception as exc:  # never raise into Blender's update loop
        fail("depsgraph update", exc)


@bpy.app.handlers.persistent
def on_load_post(*_args) -> None:
    reset()


def tick() -> float | None:
    """The timer: capture, set the quality, redraw 3D views. Returns when to run again (None: stop)."""
    try:
        if not _enabled(bpy.context.scene):
            return None
        busy = time.perf_counter() - STATE.last_event_s < IDLE_S
        changed = capture(bpy.context.evaluated_depsgraph_get())
        quality = "preview" if busy else "full"
        if changed or quality != STATE.quality:
            STATE.quality = quality
            tag_redraw()
        return IDLE_S if busy else None
    except Exception as exc:
        fail("live update", exc)
        return None


def redraw_soon() -> None:
    """Another redraw of the 3D views shortly (a draw callback asks for its next refinement so)."""
    if not bpy.app.timers.is_registered(_redraw_once):
        bpy.app.timers.register(_redraw_once, first_interval=0.0)


def _redraw_once() -> None:
    tag_redraw()


def tag_redraw() -> None:
    wm = bpy.context.window_manager
    for window in wm.windows if wm else ():
        for area in window.screen.areas if window.screen else ():
            if area.type == "VIEW_3D":
                area.tag_redraw()


def reset() -> None:
    """Forget the capture and any error (a new file, or Enabled toggled): the next update re-reads all."""
    global STATE
    STATE = LiveState()


# ----------------------------------------------------------------------------------------- registration

_HANDLERS = (("depsgraph_update_post", on_depsgraph_update), ("load_post", on_load_post))


def register() -> None:
    for name, fn in _HANDLERS:
        handlers = getattr(bpy.app.handlers, name)
        if fn not in handlers:
            handlers.append(fn)


def unregister() -> None:
    for name, fn in _HANDLERS:
        handlers = getattr(bpy.app.handlers, name)
        while fn in handlers:
            handlers.remove(fn)
    for timer in (tick, _redraw_once):
        if bpy.app.timers.is_registered(timer):
            bpy.app.timers.unregister(timer)
    reset()
