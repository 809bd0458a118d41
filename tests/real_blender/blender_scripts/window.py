"""In a real window: the overlay of each method drawing in the 3D view, screenshots, a light moved.
-- SHOT_DIR RESULT.json   (run with the Cornell .blend opened, DISPLAY set, the extension enabled)

Blender's event loop must run for a 3D view to draw, so the steps are a timer's: each returns the delay
to the next. Screenshots are the X screen (`xwd`, converted by ImageMagick): what a user sees. The
result records the 3D view's rectangle, so the test can crop it."""

import os
import subprocess
import sys
import time

sys.path.insert(0, os.path.dirname(__file__))
import _common  # noqa: E402
import bpy  # noqa: E402

WAIT_S = 120.0  # llvmpipe: vct's first update in a window takes seconds; a GPU takes milliseconds

shot_dir, result_path = _common.args()[:2]
result = {"blender": bpy.app.version_string, "methods": {}}


def shot(name):
    path = os.path.join(shot_dir, f"{name}.png")
    subprocess.run(f"xwd -root -silent -display {os.environ['BOUNCE_DISPLAY']} | convert xwd:- {path}",
                   shell=True, check=True)
    return path


def view3d():
    screen = bpy.context.window_manager.windows[0].screen
    return next(a for a in screen.areas if a.type == "VIEW_3D")


def redraw():
    view3d().tag_redraw()


def finish(error=None):
    import traceback

    if error is not None:
        result.update(ok=False, error=f"{type(error).__name__}: {error}", traceback=traceback.format_exc())
    else:
        result["ok"] = True
    _common.write(result_path, result)
    os._exit(0 if error is None else 1)


def until_updated(live, viewport, runs):
    """Delays until the overlay has drawn an update since `runs` GPU runs (or failed, or WAIT_S passed),
    then one for that frame to reach the screen; returns the seconds it all took."""
    t0 = time.perf_counter()
    while viewport.gpu_runs == runs or live.STATE.quality != "full" or bpy.app.timers.is_registered(live.tick):
        if live.STATE.error or time.perf_counter() - t0 > WAIT_S:
            break
        redraw()
        yield 0.25
    redraw()
    yield 1.0  # the updated frame reaches the screen
    return time.perf_counter() - t0


def steps():
    """A generator of delays: the timer below advances it once per call."""
    live, viewport = _common.bounce("addon.bridge.live"), _common.bounce("addon.bridge.viewport")
    area = view3d()
    space = area.spaces.active
    space.region_3d.view_perspective = "CAMERA"
    space.shading.type = "SOLID"
    space.overlay.show_overlays = False  # gizmos and grid off: only the scene and Bounce's light
    # Blender's viewport anti-aliasing converges over redraws; the overlay's progressive refinement keeps
    # asking for redraws, so shots with and without it would differ at every edge: compare without AA.
    bpy.context.preferences.system.viewport_aa = "OFF"
    window = bpy.context.window_manager.windows[0]
    result["window"] = [window.width, window.height]
    result["area"] = [area.x, area.y, area.width, area.height]
    redraw()
    yield 2.0
    result["off"] = shot("off")
    settings = bpy.context.scene.bounce
    settings.lpv.grid_cells, settings.vct.voxel_cells, settings.vct.diffuse_cones = 16, 32, 6
    spot = bpy.data.objects["Spot"]
    for method in _common.bounce("addon.engine.registry").NAMES:
        entry = result["methods"].setdefault(method, {})
        for phase in ("on", "moved"):
            runs = viewport.gpu_runs
            if phase == "on":
                settings.gi.method = method
                settings.enabled = True
            else:
                spot.location.x += 0.25  # the light moves: the overlay must follow
            wait_s = yield from until_updated(live, viewport, runs)
            entry[phase] = {"shot": shot(f"{method}_{phase}"), "status": live.status(), "error": live.STATE.error,
                            "gpu_runs": viewport.gpu_runs - runs, "wait_s": round(wait_s, 2),
                            "samples": live.STATE.samples}
            if phase == "on":  # still: the overlay keeps refining on its own (its redraws ask for more)
                yield 3.0
                entry["samples_later"] = live.STATE.samples
                entry["status_later"] = live.status()
        spot.location.x -= 0.25
        settings.enabled = False
        redraw()
        yield 0.5
    # A light with a shape (its own direct-light program, POLYGONS) in place of the spot: a 0.5 m square
    # area light under the ceiling, drawn by `direct`.
    spot.hide_viewport = spot.hide_render = True
    area_light = bpy.data.lights.new("Area", "AREA")
    area_light.size, area_light.energy = 0.5, 100.0
    area = bpy.data.objects.new("Area", area_light)
    area.location = (0.0, 0.0, 1.9)
    bpy.context.scene.collection.objects.link(area)
    settings.gi.method = "direct"
    runs = viewport.gpu_runs
    settings.enabled = True
    yield from until_updated(live, viewport, runs)
    result["area_light"] = {"shot": shot("area_light"), "status": live.status(), "error": live.STATE.error,
                            "gpu_runs": viewport.gpu_runs - runs}
    # A Base Color image texture in the combined view (light x albedo): the white surfaces take an 8 x 8
    # checker of 1 and 0, then its inverse. The two have the same mean, so only an albedo read per pixel
    # tells them apart on the screen.
    settings.view_mode = "COMBINED"
    tree = bpy.data.materials["White"].node_tree
    tex = tree.nodes.new("ShaderNodeTexImage")
    tex.interpolation = "Closest"
    link = tree.links.new(tex.outputs["Color"], tree.nodes["Principled BSDF"].inputs["Base Color"])
    entry = result["texture"] = {}
    for name, phase in (("checker", 0), ("inverse", 1)):
        image = bpy.data.images.new(name, 8, 8, float_buffer=True)
        image.pixels.foreach_set([float((i // 4 // 8 + i // 4 % 8 + phase) % 2) if i % 4 < 3 else 1.0
                                  for i in range(8 * 8 * 4)])
        tex.image = image
        runs = viewport.gpu_runs
        yield from until_updated(live, viewport, runs)
        entry[name] = {"shot": shot(f"texture_{name}"), "error": live.STATE.error,
                       "gpu_runs": viewport.gpu_runs - runs}
    tree.links.remove(link)
    settings.view_mode = "INDIRECT"
    # A sky (Blender's Sky Texture, its sun disc on: no map Bounce reads itself) instead of the lamps: the
    # overlay lights it as its average until Capture World Light renders its map and its sun, then by
    # direction.
    area.hide_viewport = area.hide_render = True
    world = bpy.data.worlds.new("Sky")
    world.use_nodes = True
    sky = world.node_tree.nodes.new("ShaderNodeTexSky")
    world.node_tree.links.new(sky.outputs["Color"], world.node_tree.nodes["Background"].inputs["Color"])
    bpy.context.scene.world = world
    runs = viewport.gpu_runs
    yield from until_updated(live, viewport, runs)
    entry = result["sky"] = {}
    entry["averaged"] = {"shot": shot("sky_averaged"), "world_averaged": settings.world_averaged,
                         "error": live.STATE.error, "gpu_runs": viewport.gpu_runs - runs}
    runs = viewport.gpu_runs
    entry["operator"] = sorted(bpy.ops.bounce.capture_world())
    yield from until_updated(live, viewport, runs)
    entry["captured"] = {"shot": shot("sky_captured"), "world_averaged": settings.world_averaged,
                         "error": live.STATE.error, "gpu_runs": viewport.gpu_runs - runs,
                         "map": live.STATE.scene.world_map is not None,
                         "sun_discs": [light.name for light in live.STATE.scene.lights if light.kind == "SUN"]}
    # Choose for Budget as the panel's button runs it (invoked: modal, its check in a second Blender on a
    # copy of the file), on the Cornell box's lamps again, at 32 px so that the check takes seconds here.
    settings.enabled = False
    bpy.context.scene.world = None
    spot.hide_viewport = spot.hide_render = False
    settings.gi.resolution, settings.error_budget, settings.choice_note = 32, 0.3, ""
    render = bpy.context.scene.render

    def render_settings():  # what the check's Cycles render sets on the scene it renders
        return [render.engine, render.resolution_x, render.resolution_y, render.film_transparent,
                bpy.context.scene.cycles.samples]
    before = render_settings()
    t0 = time.perf_counter()
    with bpy.context.temp_override(window=window, area=view3d()):
        entry = result["choose"] = {"invoked": sorted(bpy.ops.bounce.choose("INVOKE_DEFAULT"))}
    while not settings.choice_note and time.perf_counter() - t0 < WAIT_S:
        yield 0.5
    entry.update(note=settings.choice_note, row=settings.choice_row, method=settings.gi.method,
                 seconds=round(time.perf_counter() - t0, 1), render_settings_kept=render_settings() == before)


_steps = steps()


def tick():
    try:
        return next(_steps)
    except StopIteration:
        finish()
    except Exception as exc:  # noqa: BLE001 - everything is reported to the host
        finish(exc)


bpy.app.timers.register(tick, first_interval=2.0)
