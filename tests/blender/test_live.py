"""Live updates and the overlay's failure path: a moved light is one capture and one recomputation with
no mesh re-read, a moved object re-uploads, a broken method is logged once and shown in the panel, and
register/unregister leaves no handler, timer or draw handler behind."""

from __future__ import annotations

import logging
import math
import sys
from pathlib import Path

import numpy as np
import pytest

bpy = pytest.importorskip("bpy")

pytestmark = [pytest.mark.blender, pytest.mark.gpu]

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(Path(__file__).resolve().parent))
from test_viewport import captured, draw_offscreen, view_context  # noqa: E402

from addon.engine.config import RsmConfig  # noqa: E402


@pytest.fixture
def live_cornell(bounce, fresh_blend, monkeypatch):
    """Cornell box, overlay on (method rsm), captured and drawn once; IDLE_S = 0 so every capture is
    at full quality (the preview path has its own test in test_viewport.py)."""
    from bounce.addon.bridge import live, scenes, viewport

    bounce.register()
    try:
        scenes.build("cornell")
        settings = bpy.context.scene.bounce
        settings.gi.method, settings.gi.resolution = "rsm", 64
        settings.enabled = True
        ctx = view_context(bpy.context.scene, 64, 48)
        captured(live)
        draw_offscreen(viewport, ctx, 64, 48)
        monkeypatch.setattr(live, "IDLE_S", 0.0)
        yield ctx
    finally:
        bounce.unregister()


def test_moving_a_light_is_one_recomputation_without_mesh_reads(live_cornell, monkeypatch):
    from bounce.addon.bridge import live, viewport
    from bounce.addon.engine.passes import gbuffer

    gbuffer_runs = []
    monkeypatch.setattr(gbuffer, "run", lambda *a, **k: gbuffer_runs.append(1))
    before = viewport.backend().read(viewport.overlay_for(1, "full").method.direct)
    reads, captures, runs = live.STATE.cache.geometry_reads, live.STATE.captures, viewport.gpu_runs
    solves = viewport.overlay_for(1, "full").method.solves
    spot = bpy.data.objects["Spot"]
    for dx in (0.05, 0.1, 0.15):  # a drag: three updates, each through the depsgraph handler
        spot.location.x = dx
        bpy.context.view_layer.update()
        assert bpy.app.timers.is_registered(live.tick)  # one timer, however many updates
    assert live.tick() is None  # timers do not fire in background mode: run it as Blender would
    draw_offscreen(viewport, live_cornell, 64, 48)
    draw_offscreen(viewport, live_cornell, 64, 48)  # nothing new: no second solve, one refinement gather
    assert live.STATE.captures == captures + 1
    assert live.STATE.changed == ("lights",)
    assert live.STATE.cache.geometry_reads == reads  # exactly 0 meshes re-read
    method = viewport.overlay_for(1, "full").method
    assert method.solves == solves + 1 and method.samples == 2
    assert viewport.gpu_runs == runs + 2
    assert gbuffer_runs == []  # camera and geometry unchanged: only the light passes ran
    after = viewport.backend().read(viewport.overlay_for(1, "full").method.direct)
    assert np.abs(after - before).max() > 0.01  # and the light did move


def test_moving_an_object_reuploads_without_reading_its_mesh(live_cornell, monkeypatch):
    from bounce.addon.bridge import live, viewport

    method = viewport.overlay_for(1, "full").method
    uploads = []
    original = method.set_scene
    monkeypatch.setattr(method, "set_scene", lambda scene: (uploads.append(1), original(scene)))
    reads, runs = live.STATE.cache.geometry_reads, viewport.gpu_runs
    bpy.data.objects["TallBox"].location.x += 0.1
    bpy.context.view_layer.update()
    captured(live)
    draw_offscreen(viewport, live_cornell, 64, 48)
    assert live.STATE.changed == ("geometry",)
    assert live.STATE.cache.geometry_reads == reads  # a transform re-applies the matrix only
    assert uploads == [1]
    assert viewport.gpu_runs == runs + 1


class _RecordingLayout:
    """Stands in for UILayout (no UI in background mode): records props and labels."""

    def __init__(self):
        self.drawn, self.labels, self.operators = [], [], []

    def box(self, **_kwargs):
        return self

    def column(self, **_kwargs):
        return self

    def row(self, **_kwargs):
        return self

    def operator(self, idname, **_kwargs):
        self.operators.append(idname)

    def prop(self, data, name, **_kwargs):
        assert name in data.bl_rna.properties, name
        self.drawn.append(name)

    def label(self, text="", **_kwargs):
        self.labels.append(text)


def test_broken_method_logs_once_stops_and_panel_shows_why(live_cornell, monkeypatch, caplog):
    from bounce.addon.bridge import live, viewport
    from bounce.panels.viewport import draw_settings

    def broken(*_args, **_kwargs):
        raise RuntimeError("shader exploded")

    # Every method's compute() is DirectMethod.compute (RsmMethod inherits it).
    monkeypatch.setattr(viewport.methods.direct.DirectMethod, "compute", broken)
    bpy.data.objects["Spot"].location.x += 0.1
    bpy.context.view_layer.update()
    captured(live)
    with caplog.at_level(logging.ERROR):
        for _ in range(3):
            draw_offscreen(viewport, live_cornell, 64, 48)  # never raises
    assert len([r for r in caplog.records if "viewport overlay" in r.getMessage()]) == 1
    settings = bpy.context.scene.bounce
    assert "shader exploded" in live.STATE.error
    assert settings.status == "Error: viewport overlay: RuntimeError: shader exploded"
    layout = _RecordingLayout()
    draw_settings(layout, settings)
    assert layout.labels[-1] == settings.status  # the status line comes last, after the lights list
    # The settings, then one include switch per lamp (the Cornell box has one spot).
    assert layout.drawn == ["method", "quality", "view_mode", "exposure", "strength", "last_update_ms",
                            "bounce_include"]
    # Stopped: the depsgraph handler schedules nothing, the overlay adds nothing.
    if bpy.app.timers.is_registered(live.tick):
        bpy.app.timers.unregister(live.tick)
    bpy.data.objects["Spot"].location.x += 0.1
    bpy.context.view_layer.update()
    assert not bpy.app.timers.is_registered(live.tick)
    assert np.all(draw_offscreen(viewport, live_cornell, 64, 48)[..., :3] == np.float32([0.1, 0.2, 0.3]))
    # Toggling Enabled clears the error.
    settings.enabled = False
    settings.enabled = True
    assert live.STATE.error is None and not settings.status.startswith("Error")


def test_a_sky_lights_as_its_average_until_captured_then_by_direction(live_cornell):
    # The overlay never renders the world from its timer: a node-tree world lights as its average and the
    # panel offers Capture World Light. The operator renders its map; the next capture lights by direction
    # (a lights change: the light passes run again, no mesh re-read) and the panel's row goes away.
    from bounce.addon.bridge import live, viewport, world_capture
    from bounce.panels.viewport import draw_settings
    from test_world_capture import _direction_world

    world_capture.forget()
    bpy.context.scene.world = _direction_world()
    bpy.context.view_layer.update()
    captured(live)
    settings = bpy.context.scene.bounce
    assert live.STATE.scene.world_map is None and settings.world_averaged
    layout = _RecordingLayout()
    draw_settings(layout, settings)
    assert layout.operators == ["bounce.capture_world"]
    draw_offscreen(viewport, live_cornell, 64, 48)
    reads, solves = live.STATE.cache.geometry_reads, viewport.overlay_for(1, "full").method.solves

    assert bpy.ops.bounce.capture_world() == {"FINISHED"}
    assert world_capture.STORED_KEY in bpy.context.scene.world  # kept in the world: saved with the file
    captured(live)
    draw_offscreen(viewport, live_cornell, 64, 48)
    assert live.STATE.changed == ("lights",) and not settings.world_averaged
    method = viewport.overlay_for(1, "full").method
    assert method.source.world_map is live.STATE.scene.world_map is not None
    assert method.solves == solves + 1 and live.STATE.cache.geometry_reads == reads
    layout = _RecordingLayout()
    draw_settings(layout, settings)
    assert layout.operators == []


def test_the_worlds_map_is_part_of_the_lights(bounce):
    # Turning a sky's sun keeps the world's average colour: the map itself must be compared, or the
    # overlay would keep the old light.
    from bounce.addon.bridge import live
    from bounce.addon.engine.scene import Scene

    def scene(world_map):
        tri = np.zeros((1, 3, 3), np.float32)
        return Scene(tri, tri.copy(), np.ones((1, 3), np.float32), np.zeros((1, 3), np.float32),
                     world_color=np.full(3, 0.5, np.float32), world_map=world_map)

    sky = np.zeros((32, 64, 3), np.float32)
    sky[:16] = 1.0
    assert live._lights(scene(sky)) != live._lights(scene(sky[::-1].copy()))
    assert live._lights(scene(sky)) == live._lights(scene(sky.copy()))
    assert live._lights(scene(sky)) != live._lights(scene(None))


def test_quality_preset_sets_rsm_settings(bounce, fresh_blend):
    bounce.register()
    try:
        settings = bpy.context.scene.bounce
        rsm = settings.rsm
        settings.quality = "HIGH"
        assert (rsm.resolution, rsm.vpl_samples, rsm.visibility, rsm.sky_rays) == (256, 256, "voxel", 8)
        settings.quality = "DRAFT"
        assert (rsm.resolution, rsm.vpl_samples, rsm.visibility, rsm.sky_rays) == (256, 64, "none", 0)
        settings.quality = "BALANCED"  # RsmConfig's defaults: sky rays auto (-1)
        default = RsmConfig()
        assert (rsm.resolution, rsm.vpl_samples, rsm.visibility, rsm.sky_rays) == (
            default.resolution, default.vpl_samples, default.visibility, default.sky_rays) == (256, 256, "none", -1)
    finally:
        bounce.unregister()


def _handler_counts() -> dict[str, int]:
    handlers = bpy.app.handlers
    return {name: len(getattr(handlers, name)) for name in dir(handlers) if isinstance(getattr(handlers, name), list)}


def test_register_unregister_with_live_overlay_leaves_nothing_behind(bounce, fresh_blend):
    from bounce.addon.bridge import live, viewport

    before = _handler_counts()
    for _ in range(2):
        bounce.register()
        try:
            assert live.on_depsgraph_update in bpy.app.handlers.depsgraph_update_post
            assert live.on_load_post in bpy.app.handlers.load_post
            assert viewport._handle is not None
            bpy.context.scene.bounce.enabled = True
            bpy.context.view_layer.update()  # the handler runs and schedules the timer
            assert bpy.app.timers.is_registered(live.tick)
        finally:
            bounce.unregister()
        assert _handler_counts() == before
        assert not bpy.app.timers.is_registered(live.tick)
        assert viewport._handle is None  # draw_handler_remove ran (Blender lists no draw handlers)
    assert live.STATE.scene is None and math.isinf(live.STATE.last_event_s)
