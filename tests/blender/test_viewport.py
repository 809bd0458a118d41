"""The viewport overlay: its draw callback renders into a GPUOffScreen with a real camera on the Cornell
box, and what it adds is checked per pixel; the Blender-gpu run of each method equals the moderngl run.

The add-on is imported as the package `bounce` (a symlink to the repository), as Blender imports it, so
the relative imports between addon/, operators/ and panels/ resolve and scene.bounce is registered.
"""

from __future__ import annotations

import contextlib
import math
import types
from pathlib import Path

import numpy as np
import pytest

bpy = pytest.importorskip("bpy")

pytestmark = [pytest.mark.blender, pytest.mark.gpu]

ROOT = Path(__file__).resolve().parents[2]
W, H = 128, 96  # the region; gi.resolution = 128 makes the overlay's images exactly this size
CLEAR = (0.1, 0.2, 0.3, 1.0)


class _Region:
    """What the callback reads of bpy.types.Region (there are no regions in background mode)."""

    def __init__(self, width, height):
        self.width, self.height = width, height

    def as_pointer(self):
        return 1


def view_context(scene, width=W, height=H, location=(0.0, -6.0, 1.0)):
    """A context as the POST_VIEW callback sees it: region size, region_data's view and window matrices
    (here a camera 6 m in front of the box looking at its centre, so background surrounds the box)."""
    cam = scene.camera
    cam.location = location
    direction = (0.0, 0.0, 1.0) - np.array(location)
    from mathutils import Vector

    cam.rotation_euler = Vector(direction).to_track_quat("-Z", "Y").to_euler()
    bpy.context.view_layer.update()
    depsgraph = bpy.context.evaluated_depsgraph_get()
    region_data = types.SimpleNamespace(view_matrix=cam.matrix_world.inverted(),
                                        window_matrix=cam.calc_matrix_camera(depsgraph, x=width, y=height))
    return types.SimpleNamespace(scene=scene, region=_Region(width, height), region_data=region_data)


def captured(live) -> None:
    """Run the live timer's work now (timers never fire in background mode), at full quality."""
    live.STATE.last_event_s = -math.inf
    assert live.tick() is None
    if bpy.app.timers.is_registered(live.tick):
        bpy.app.timers.unregister(live.tick)


def draw_offscreen(viewport, ctx, width=W, height=H) -> np.ndarray:
    """Call the draw callback with an RGBA32F offscreen bound, cleared to CLEAR; (h, w, 4), row 0 bottom."""
    import gpu

    viewport.backend()  # initialises Blender's gpu module in background mode
    offscreen = gpu.types.GPUOffScreen(width, height, format="RGBA32F")
    try:
        with offscreen.bind():
            fb = gpu.state.active_framebuffer_get()
            fb.clear(color=CLEAR)
            viewport.draw_callback(ctx)
            return np.array(fb.read_color(0, 0, width, height, 4, 0, "FLOAT").to_list(), np.float32)
    finally:
        offscreen.free()


@contextlib.contextmanager
def overlay_on(bounce, scene_name: str, method: str, edit=lambda: None):
    """The add-on registered, procedural scene `scene_name` built (then `edit()`), the overlay enabled
    with `method` at the region's size, captured: yields the draw context; unregisters after."""
    from bounce.addon.bridge import live, scenes

    bounce.register()
    try:
        scenes.build(scene_name)
        edit()
        settings = bpy.context.scene.bounce
        settings.gi.method = method
        settings.gi.resolution = max(W, H)
        settings.enabled = True
        ctx = view_context(bpy.context.scene)
        captured(live)
        yield ctx
    finally:
        bounce.unregister()


@pytest.fixture
def cornell(bounce, fresh_blend):
    """The Cornell box with the overlay enabled, method rsm (overlay_on)."""
    with overlay_on(bounce, "cornell", "rsm") as ctx:
        yield ctx


def _textures(viewport, method) -> dict[str, np.ndarray]:
    be = viewport.backend()
    return {"albedo": be.read(method.gbuf["albedo"]), "direct": be.read(method.direct),
            "indirect": be.read(method.indirect)}


@pytest.mark.parametrize("mode, w_direct, w_indirect",
                         [("COMBINED", 1, 1), ("INDIRECT", 0, 1), ("DIRECT", 1, 0)])
def test_overlay_adds_albedo_times_light_times_exposure(cornell, mode, w_direct, w_indirect):
    from bounce.addon.bridge import live, viewport

    settings = cornell.scene.bounce
    settings.view_mode, settings.exposure, settings.strength = mode, 1.5, 0.7
    runs = viewport.gpu_runs
    pixels = draw_offscreen(viewport, cornell)
    assert live.STATE.error is None
    assert viewport.gpu_runs == runs + 1
    tex = _textures(viewport, viewport.overlay_for(1, "full").method)
    assert tex["albedo"].shape == (H, W, 4)  # the overlay ran at the region's size: texel = pixel

    added = pixels - np.array(CLEAR, np.float32)
    geometry = tex["albedo"][..., 3] > 0
    # A camera 6 m away sees the box in the middle and nothing around it.
    assert 0.2 < geometry.mean() < 0.8
    # Nothing where the G-buffer saw no geometry: albedo 0 there, so exactly 0 is added (and alpha never).
    assert np.all(added[~geometry] == 0.0)
    assert np.all(added[..., 3] == 0.0)
    # Light everywhere on the box: the spot's direct light on the floor, indirect on every wall.
    lit = (added[geometry][:, :3].sum(axis=1) > 0).mean()
    assert lit > (0.1 if mode == "DIRECT" else 0.95), lit
    assert added.max() > 0.5

    expected = tex["albedo"][..., :3] * (w_direct * tex["direct"][..., :3] + w_indirect * tex["indirect"][..., :3])
    expected *= 2.0 ** 1.5 * 0.7
    # The full-screen triangle's uv lands on texel centres, where linear filtering returns the texel
    # itself, up to the rounding of the interpolated uv: at edges, where a neighbour texel differs a lot,
    # a tiny fraction of it leaks in (measured: 0.4 % of pixels, at most 5.6e-6 absolute against values
    # up to ~2). Hence rtol 1e-5 (fp32 maths in another order) and atol 2e-5 (1e-5 of the brightest).
    np.testing.assert_allclose(added[..., :3], expected, rtol=1e-5, atol=1e-5 * expected.max())


def test_redraw_without_changes_does_not_recompute(cornell, monkeypatch):
    from bounce.addon.bridge import viewport

    monkeypatch.setattr(viewport, "MAX_SAMPLES", 1)  # no progressive refinement: the next test's subject
    first = draw_offscreen(viewport, cornell)
    runs = viewport.gpu_runs
    cornell.scene.bounce.exposure = 1.0  # a display setting: redraw only
    second = draw_offscreen(viewport, cornell)
    assert viewport.gpu_runs == runs
    clear = np.array(CLEAR, np.float32)
    # Exposure 0 -> 1 doubles what is added (fp32 sums with the clear colour: a few ulp of ~2).
    np.testing.assert_allclose(second[..., :3] - clear[:3], 2.0 * (first[..., :3] - clear[:3]), rtol=1e-5, atol=1e-6)


def test_still_view_refines_progressively(cornell):
    # Nothing changes: each redraw averages one more gather (no solve, no G-buffer), the panel says how
    # many, and successive images differ less and less (the mean of n gathers moves by ~1/n per sample).
    from bounce.addon.bridge import live, viewport

    images = [draw_offscreen(viewport, cornell)]
    method = viewport.overlay_for(1, "full").method
    solves = method.solves
    for _ in range(7):
        images.append(draw_offscreen(viewport, cornell))
    assert method.samples == 8 and method.solves == solves
    assert "8 sample(s)" in live.status()
    steps = [float(np.abs(b - a).mean()) for a, b in zip(images, images[1:], strict=False)]
    assert steps[-1] < 0.5 * steps[0], steps
    assert bpy.app.timers.is_registered(live._redraw_once)  # the next refinement is asked for


def test_a_method_that_cannot_refine_stops_asking_for_redraws(cornell, monkeypatch):
    # Refinement needs the kept light field; where it cannot run, the still view must go quiet instead of
    # redrawing forever.
    from bounce.addon.bridge import live, viewport
    from bounce.addon.engine.methods.direct import DirectMethod

    draw_offscreen(viewport, cornell)
    monkeypatch.setattr(DirectMethod, "refine", lambda self: {})
    if bpy.app.timers.is_registered(live._redraw_once):
        bpy.app.timers.unregister(live._redraw_once)
    draw_offscreen(viewport, cornell)
    assert not bpy.app.timers.is_registered(live._redraw_once)


def test_navigating_gives_preview_then_full_quality(cornell):
    from bounce.addon.bridge import live, viewport

    draw_offscreen(viewport, cornell)
    moved = view_context(cornell.scene, location=(0.5, -6.0, 1.2))
    draw_offscreen(viewport, moved)  # the view changed: preview at half size, a full update scheduled
    assert bpy.app.timers.is_registered(live.tick)
    preview = viewport.overlay_for(1, "preview").camera
    assert (preview.width, preview.height) == (W // 2, H // 2)
    captured(live)  # idle now: full quality
    assert live.STATE.quality == "full"
    runs = viewport.gpu_runs
    draw_offscreen(viewport, moved)
    assert viewport.gpu_runs == runs + 1
    full = viewport.overlay_for(1, "full").camera
    assert (full.width, full.height) == (W, H)
    np.testing.assert_array_equal(full.view, preview.view)


@pytest.mark.parametrize("name", ["direct", "direct-world", "direct-area", "direct-emissive", "rsm", "lpv",
                                  "lpv-far-field", "lpv-emitter-classes",
                                  "lpv-octree", "lpv-octree-index", "vct", "vct-filtered", "diffusion",
                                  "diffusion-far-field", "probes",
                                  "probes-irradiance", "probes-relocate", "probes-area", "gather", "gather-point"])
def test_blender_gpu_run_equals_moderngl_run(gl, blender_backend, fresh_blend, name):
    # lpv at 16 cells runs one grid; "lpv-far-field" at 32 cells adds the far field's passes;
    # "diffusion-far-field" (32 cells) diffusion's: the far grid's voxels, cells, weights, emitters
    # (moved where enclosed), its steps by face (eight images) and their share onto the fine sides;
    # "lpv-emitter-classes" (16 cells) the classes' injection, unpacks and own-light lookups;
    # "lpv-octree" (16 cells) every level's injection and the time merge, "lpv-octree-index" the
    # downsampling and the index merge's shader;
    # "vct-filtered" the filtered injection (gl_VertexID, the projected-area fetches);
    # "direct-world" the sky's shadow atlas (a draw per tile's viewport) and its fused direct pass;
    # "direct-area" and "direct-emissive" the direct pass of lights with a shape (its POLYGONS program,
    # which reads fewer uniforms than a point's: the compiler drops the rest);
    # "gather-point" the gather's point-to-point form factor; "probes-relocate" the relocation step,
    # the moved probes' tiles cleared and drawn again, and every probe shader at the moved positions;
    # "probes-area" the grazing texels' footprints and the atlas's area-sampled direct pass of a light
    # with a shape (the program with the most samplers).
    from addon.bridge import scenes
    from addon.bridge.capture import SceneCache
    from addon.engine import methods
    from addon.engine.config import (
        DiffusionConfig,
        GatherConfig,
        GIConfig,
        LpvConfig,
        ProbesConfig,
        RsmConfig,
        VctConfig,
    )

    # vct: its glossy product too; direct-world: Blender's default grey world besides the spot.
    scene_of = {"direct-world": "cornell-grey-world", "direct-area": "cornell-large-area",
                "direct-emissive": "emissive", "probes-area": "cornell-large-area"}
    scenes.build(scene_of.get(name, "cornell-glossy" if name.startswith("vct") else "cornell"))
    scene = SceneCache().update(bpy.context.evaluated_depsgraph_get(), 64, 48)
    method_name, grid_cells = (name.split("-")[0], 32) if name.endswith("far-field") else (name.split("-")[0], 16)
    gi = GIConfig(method=method_name, resolution=64)
    rsm = RsmConfig(resolution=128, vpl_samples=64)
    results = []
    for be in (gl, blender_backend):
        lpv = LpvConfig(grid_cells=grid_cells, variant="octree" if "octree" in name else "improved",
                        geometry_volume=True, emitter_classes=name == "lpv-emitter-classes",
                        octree_merge="index" if name == "lpv-octree-index" else "time")
        vct = VctConfig(voxel_cells=16, diffuse_cones=6, filtered_injection=name == "vct-filtered")
        method = methods.create(be, {"gi": gi, "rsm": rsm, "lpv": lpv, "vct": vct,
                                     "diffusion": DiffusionConfig(grid_cells=grid_cells),
                                     "probes": ProbesConfig(probes_per_side=6, encoding="irradiance"
                                                            if name == "probes-irradiance" else "sh",
                                                            relocate=name == "probes-relocate",
                                                            area_samples=4 if name == "probes-area" else 1),
                                     "gather": GatherConfig(form_factor="point" if name == "gather-point"
                                                            else "polygon")})
        method.set_scene(scene)
        result = method.run()
        assert ("sky_direct" in result.timings_ms) == (name == "direct-world")  # the world lights, via the sky pass
        results.append(result.images)
    a, b = results
    assert set(a) == set(b) == set(methods.get(method_name).products)
    for key in a:
        assert a[key][..., :3].max() > 0, key  # light, not just the coverage in alpha
        # Same GLSL bodies, same Mesa rasterizer and fp32 maths on both: equal to float32 rounding,
        # the gather's hash gives both the same VPLs. rtol 1e-4: vct on cornell-glossy differs in 24 of
        # 12288 values by up to 4.5e-5 (rounding accumulated over cones and steps); the rest by < 1e-5.
        np.testing.assert_allclose(b[key], a[key], rtol=1e-4, atol=1e-6, err_msg=key)


@pytest.mark.parametrize("scene_name", ["cornell-sun", "cornell-point", "cornell-large-area", "emissive", "window-sky"])
@pytest.mark.parametrize("method_name", ["direct", "rsm", "lpv", "vct", "diffusion", "probes", "gather"])
def test_every_method_under_every_kind_of_light_equals_moderngl(gl, blender_backend, fresh_blend, scene_name,
                                                                 method_name):
    # The light kinds of the benchmark scenes (a sun, a point's six faces, an area light's patches, an
    # emissive mesh's lamps, a sky and a sun through a window) through every method, at small settings.
    # Blender's depth test was LESS_EQUAL where moderngl's is LESS: texels where two surfaces tie in
    # depth (a probe face looking into a room's corner, an area patch's RSM faces) took the other
    # surface: 6 of these 35 differed, probes by up to 2.8 % and gather by up to 18 % on window-sky,
    # rsm, lpv and vct by up to 0.35 % on cornell-large-area (measured).
    from addon.bridge import scenes
    from addon.bridge.capture import SceneCache
    from addon.engine import methods
    from addon.engine.config import DiffusionConfig, GIConfig, LpvConfig, ProbesConfig, RsmConfig, VctConfig

    scenes.build(scene_name)
    scene = SceneCache().update(bpy.context.evaluated_depsgraph_get(), 64, 48)
    results = []
    for be in (gl, blender_backend):
        method = methods.create(be, {"gi": GIConfig(method=method_name, resolution=64),
                                     "rsm": RsmConfig(resolution=128, vpl_samples=64),
                                     "lpv": LpvConfig(grid_cells=16), "vct": VctConfig(voxel_cells=16, diffuse_cones=6),
                                     "diffusion": DiffusionConfig(grid_cells=16),
                                     "probes": ProbesConfig(probes_per_side=4)})
        method.set_scene(scene)
        results.append(method.run().images)
    a, b = results
    for key in a:
        assert key == "glossy" or a[key][..., :3].max() > 0, key  # these scenes have no glossy surfaces
        # As test_blender_gpu_run_equals_moderngl_run: the same GLSL on the same rasterizer.
        np.testing.assert_allclose(b[key], a[key], rtol=1e-4, atol=1e-6, err_msg=key)


def test_voxels_view_shows_the_grid_on_the_surfaces(cornell):
    # The Cornell box's surfaces are closed and voxelized conservatively: every visible surface point
    # lies in an occupied voxel, so no pixel is magenta (a hole); the colours are the voxel albedos
    # (white walls 0.725, 0.71, 0.68 and the red/green walls) times the checkerboard's 0.7 or 1.0.
    from bounce.addon.bridge import viewport

    cornell.scene.bounce.view_mode = "VOXELS"
    pixels = draw_offscreen(viewport, cornell)
    method = viewport.overlay_for(1, "full").method
    geometry = viewport.backend().read(method.gbuf["albedo"])[..., 3] > 0
    added = (pixels - np.array(CLEAR, np.float32))[..., :3]
    assert np.all(added[~geometry] == 0.0)
    shown = added[geometry]
    magenta = (shown[:, 0] > 0.9) & (shown[:, 1] < 0.1) & (shown[:, 2] > 0.9)
    assert magenta.mean() < 0.001
    white = np.array([0.725, 0.71, 0.68])
    close_to = [np.abs(shown - white * k).max(axis=1) < 1e-3 for k in (0.7, 1.0)]
    assert (close_to[0] | close_to[1]).mean() > 0.5  # most surfaces are white; both parities appear
    assert close_to[0].any() and close_to[1].any()


@pytest.mark.parametrize("method, view, shown", [("lpv", "VOXELS", "INDIRECT"), ("direct", "INDIRECT", "DIRECT"),
                                                 ("direct", "VOXELS", "DIRECT")])
def test_view_a_method_cannot_show_falls_back_with_a_note(cornell, method, view, shown):
    # The overlay keeps drawing (no error, light added) what the method has, and the panel says why.
    from bounce.addon.bridge import live, viewport

    settings = cornell.scene.bounce
    settings.gi.method, settings.gi.resolution, settings.lpv.grid_cells = method, 32, 16
    settings.view_mode = view
    pixels = draw_offscreen(viewport, cornell)
    assert live.STATE.error is None
    assert viewport.shown_view(viewport.overlay_for(1, "full").method, view)[0] == shown
    assert (pixels - np.array(CLEAR, np.float32))[..., :3].max() > 0.1
    assert method in live.status() and ("Voxels" in live.status() or "no indirect" in live.status())
    settings.view_mode = shown  # a view it can show: the note goes
    draw_offscreen(viewport, cornell)
    assert live.STATE.note is None


def test_excluded_light_is_left_out(bounce, fresh_blend):
    # Light > Bounce unticked: the capture leaves the lamp out, and the switch survives a save/reload
    # and is honoured without the add-on registered (the CLI), through the saved ID property.
    from bounce.addon.bridge import capture, scenes

    bounce.register()
    try:
        scenes.build("cornell")
        assert len(capture.capture(bpy.context.evaluated_depsgraph_get()).lights) == 1
        bpy.data.lights["Spot"].bounce_include = False
        bpy.context.view_layer.update()  # the evaluated copy the capture reads
        assert capture.capture(bpy.context.evaluated_depsgraph_get()).lights == []
    finally:
        bounce.unregister()
    assert not hasattr(bpy.types.Light, "bounce_include")
    capture.define_light_switch()  # what the CLI does: the saved value is readable again
    assert capture.light_included(bpy.data.lights["Spot"]) is False
    del bpy.types.Light.bounce_include


def test_the_viewport_keeps_the_sky_filter_for_auto_rays(bounce, fresh_blend):
    # RsmConfig.sky_rays' default, auto (-1), traces rays in renders and bakes where the world gives
    # most of the light (sky_light.rays_for; here all of it: the grey-world box without its spot); the
    # live viewport runs the filter instead (sky_light.viewport_rays), and a number set by hand is kept.
    from bounce.addon.bridge import live, viewport

    def without_lamps():
        for obj in [o for o in bpy.context.scene.objects if o.type == "LIGHT"]:
            bpy.data.objects.remove(obj)

    with overlay_on(bounce, "cornell-grey-world", "direct", without_lamps) as ctx:
        settings = bpy.context.scene.bounce
        assert settings.rsm.sky_rays == -1
        draw_offscreen(viewport, ctx)
        assert live.STATE.error is None
        method = viewport.overlay_for(1, "full").method
        assert method.rsm_config.sky_rays == 0 and method.sky().rays == 0
        settings.rsm.sky_rays = 8
        draw_offscreen(viewport, ctx)
        method = viewport.overlay_for(1, "full").method
        assert method.rsm_config.sky_rays == 8 and method.sky().rays == 8
