"""Viewport overlay: Bounce's light drawn additively over each 3D view (a SpaceView3D POST_VIEW handler).

Per region and quality an `Overlay` owns a method instance (direct, rsm or lpv) on the Blender gpu backend,
rendered with the region's own camera: view = `region_data.view_matrix`, projection =
`region_data.window_matrix`, at the region's size capped to `gi.resolution` on its long side (halved in
preview quality). The draw adds (albedo x (indirect [+ direct]) [+ glossy]) x 2^exposure x strength
with (ONE, ONE) blending over whatever the viewport drew.

Depth: no depth test. The overlay's G-buffer is the scene as captured, so where it saw no geometry the
albedo is 0 and nothing is added; what the viewport draws on top of the scene (gizmos, objects hidden
from render) is not occluded. Drawn after the scene, the overlay needs no access to the viewport's depth,
which the Python API does not expose portably.

The GPU work runs inside the draw callback because only there is a GPU context certain on every Blender
backend; `live` only captures and says what changed, so a light edit re-runs only the light passes and
an unchanged view redraws without recomputing. The callback never raises into Blender: an error is
logged once, the overlay stops and `live.STATE.error` holds the reason for the panel.
"""

from __future__ import annotations

import collections
import contextlib
import dataclasses
import time

import bpy
import gpu
import numpy as np

from ..engine import methods
from ..engine.backends.base import Sampler, ShaderSpec, Var
from ..engine.passes import sky_light
from ..engine.scene import Camera
from ..properties import to_config
from . import live
from .blender_gpu_backend import BlenderGPUBackend

PRESENT = ShaderSpec(
    name="present",
    vertex="present/present.vert.glsl",
    fragment="present/present.frag.glsl",
    samplers=(Sampler("albedo_tex", "2D"), Sampler("direct_tex", "2D"), Sampler("indirect_tex", "2D"),
              Sampler("glossy_tex", "2D")),
    uniforms=(Var("scale", "float"), Var("w_direct", "float"), Var("w_indirect", "float"), Var("use_albedo", "float"),
              Var("w_glossy", "float")),
    attributes=(Var("pos_ndc", "vec2"),),
    varyings=(Var("uv", "vec2"),),
    outputs=(Var("frag_color", "vec4"),),
)
FULL_SCREEN_TRIANGLE = np.array([[-1.0, -1.0], [3.0, -1.0], [-1.0, 3.0]], np.float32)

# view_mode -> (weight of direct, weight of indirect); VOXELS shows the rsm method's voxel grid instead.
MODE_WEIGHTS = {"COMBINED": (1.0, 1.0), "INDIRECT": (0.0, 1.0), "DIRECT": (1.0, 0.0), "VOXELS": (0.0, 1.0)}
PREVIEW_SCALE = 0.5        # preview quality: half the resolution ...
PREVIEW_VPL_DIVISOR = 4    # ... and a quarter of the VPLs: ~8x less gather work while a light is dragged,
# each pixel sampled once however small the image (GIConfig.sample_budget_px 0): the still view's first
# update takes the samples, refinement the rest
MAX_OVERLAYS = 8           # (region, quality) pairs kept; regions come and go with the UI layout
MAX_SAMPLES = 64           # gathers averaged while nothing changes (progressive refinement, rsm and vct)

_backend: BlenderGPUBackend | None = None
_overlays: collections.OrderedDict = collections.OrderedDict()
_views: dict[int, tuple] = {}  # region -> last (view, window) matrices, to notice navigation
_handle = None
gpu_runs = 0  # how many times an overlay recomputed (tests count recomputations with it)


def backend() -> BlenderGPUBackend:
    global _backend
    if _backend is None:
        _backend = BlenderGPUBackend()
    return _backend


# ---------------------------------------------------------------------------------------------- camera

def view_size(region_w: int, region_h: int, long_side: int, quality: str) -> tuple[int, int]:
    """The overlay's image size: the region's aspect, long side at most `long_side`, halved in preview."""
    s = min(1.0, long_side / max(region_w, region_h, 1))
    if quality == "preview":
        s *= PREVIEW_SCALE
    return max(1, round(region_w * s)), max(1, round(region_h * s))


def region_camera(view_matrix, window_matrix, width: int, height: int, scale_length: float = 1.0) -> Camera:
    """Engine camera (metres) from a region's view and window matrices (Blender units), as
    capture.camera_for does for camera objects: view_m = S V S^-1, projection_m = P S^-1."""
    s = scale_length or 1.0
    S, S_inv = np.diag([s, s, s, 1.0]), np.diag([1 / s, 1 / s, 1 / s, 1.0])
    view = np.array(view_matrix, dtype=np.float64)
    proj = np.array(window_matrix, dtype=np.float64)
    return Camera(view=S @ view @ S_inv, projection=proj @ S_inv, width=int(width), height=int(height))


def _same_camera(a: Camera | None, b: Camera) -> bool:
    return (a is not None and (a.width, a.height) == (b.width, b.height)
            and np.array_equal(a.view, b.view) and np.array_equal(a.projection, b.projection))


# ------------------------------------------------------------------------------------------- computing

class Overlay:
    """One region at one quality: a method whose textures have the overlay's size, and the versions of
    the capture and camera they were computed from."""

    def __init__(self):
        self.method = None
        self.configs = None
        self.camera: Camera | None = None
        self.geometry_version = self.lights_version = -1

    def update(self, state: live.LiveState, camera: Camera, settings: dict) -> bool:
        """Bring the images up to date for {group: config} settings; False when they already were. The
        method decides what to re-run (a camera move gathers from its kept light field)."""
        if self.method is None or self.configs != settings:
            self.method, self.configs = methods.create(backend(), settings), settings
            self.method.profile = False  # no GPU sync per pass: the callback times the whole update
            self.geometry_version = -1
        if self.geometry_version != state.geometry_version:
            self.method.set_scene(dataclasses.replace(state.scene, camera=camera))  # upload geometry
            run_gbuffer = True
        elif self.lights_version != state.lights_version or not _same_camera(self.camera, camera):
            # Geometry on the GPU is still valid: only the camera and the lights are new.
            self.method.set_camera(camera)
            self.method.set_lights(state.scene.lights)
            self.method.set_world(state.scene.world_color, state.scene.world_map)
            run_gbuffer = not _same_camera(self.camera, camera)
        else:
            return False
        self.camera, self.geometry_version, self.lights_version = camera, state.geometry_version, state.lights_version
        self.method.compute(run_gbuffer)
        return True


def overlay_for(region_key: int, quality: str) -> Overlay:
    key = (region_key, quality)
    if key not in _overlays:
        _overlays[key] = Overlay()
        while len(_overlays) > MAX_OVERLAYS:
            _overlays.popitem(last=False)
    _overlays.move_to_end(key)
    return _overlays[key]


# ---------------------------------------------------------------------------------------------- drawing

@contextlib.contextmanager
def _restored_gpu_state():
    """The passes bind their own framebuffers, viewports and blend modes; Blender's drawing continues
    after the callback with what it had set."""
    viewport = gpu.state.viewport_get()
    blend, depth_test, depth_mask = gpu.state.blend_get(), gpu.state.depth_test_get(), gpu.state.depth_mask_get()
    try:
        yield
    finally:
        gpu.state.viewport_set(*viewport)
        gpu.state.blend_set(blend)
        gpu.state.depth_test_set(depth_test)
        gpu.state.depth_mask_set(depth_mask)


_present_batch = None


def shown_view(method, view_mode: str) -> tuple[str, str | None]:
    """The view the overlay can show for this method, and a note when it is not the one asked for,
    instead of stopping the overlay or adding nothing: the Voxels view needs the rsm method's voxel
    grid (others show their indirect light), and the Indirect view a method with indirect light
    (`direct` shows its direct light)."""
    if view_mode == "VOXELS" and not hasattr(method, "voxel_view"):
        view_mode, note = "INDIRECT", f"the Voxels view needs method rsm; {method.name} shows its indirect light"
    else:
        note = None
    if view_mode == "INDIRECT" and getattr(method, "indirect", None) is None:
        return "DIRECT", f"{method.name} computes no indirect light: showing its direct light"
    return view_mode, note


def present(method, view_mode: str, exposure: float, strength: float) -> None:
    """Add (albedo x (w_d direct + w_i indirect) + w_i glossy) x 2^exposure x strength to the bound
    framebuffer; glossy (vct's reflected light, already radiance) only where the method has it.
    `view_mode` must be one the method can show (`shown_view`)."""
    global _present_batch
    prog = backend().program(PRESENT)
    if _present_batch is None:
        _present_batch = backend().mesh(prog, {"pos_ndc": FULL_SCREEN_TRIANGLE}, "triangles").batch
    w_direct, w_indirect = MODE_WEIGHTS[view_mode]
    use_albedo = 1.0
    if view_mode == "VOXELS":
        indirect, use_albedo = method.voxel_view(), 0.0
    else:
        indirect = getattr(method, "indirect", None)
    if indirect is None:  # a method without indirect light: the sampler needs some texture
        indirect, w_indirect = method.direct, 0.0
    glossy, w_glossy = getattr(method, "glossy", None), (w_indirect if view_mode != "VOXELS" else 0.0)
    if glossy is None:
        glossy, w_glossy = method.direct, 0.0
    shader = prog.gl
    with _restored_gpu_state():
        gpu.state.blend_set("ADDITIVE_PREMULT")  # (ONE, ONE); 'ADDITIVE' would scale by alpha
        gpu.state.depth_test_set("NONE")
        gpu.state.depth_mask_set(False)
        shader.bind()
        shader.uniform_float("scale", float(2.0 ** exposure * strength))
        shader.uniform_float("w_direct", w_direct)
        shader.uniform_float("w_indirect", w_indirect)
        shader.uniform_float("use_albedo", use_albedo)
        shader.uniform_float("w_glossy", w_glossy)
        shader.uniform_sampler("albedo_tex", method.gbuf["albedo"].gl)
        shader.uniform_sampler("direct_tex", method.direct.gl)
        shader.uniform_sampler("indirect_tex", indirect.gl)
        shader.uniform_sampler("glossy_tex", glossy.gl)
        _present_batch.draw(shader)


def draw_callback(context=None) -> None:
    """The POST_VIEW handler. `context` is for tests (an object with scene, region, region_data)."""
    context = context or bpy.context
    settings = getattr(context.scene, "bounce", None)
    if settings is None or not settings.enabled or live.STATE.error:
        return
    try:
        _draw(context, settings)
    except Exception as exc:  # never raise into Blender's drawing: log once, stop, tell the panel
        live.fail("viewport overlay", exc)


def _draw(context, settings) -> None:
    global gpu_runs
    state = live.STATE
    if state.scene is None or state.scene_name != context.scene.name:
        live.request()  # nothing captured yet: the timer captures, then redraws
        return
    region, rv3d = context.region, context.region_data
    region_key = region.as_pointer()
    matrices = (np.array(rv3d.view_matrix), np.array(rv3d.window_matrix))
    last = _views.get(region_key)
    moved = last is not None and not all(np.array_equal(a, b) for a, b in zip(last, matrices, strict=True))
    _views[region_key] = matrices
    if moved:
        live.touch()  # navigating is interaction too: preview now, full quality once it stops
    quality = "preview" if moved or state.quality == "preview" else "full"
    configs = to_config(settings)
    configs["rsm"] = dataclasses.replace(configs["rsm"], sky_rays=sky_light.viewport_rays(configs["rsm"].sky_rays))
    gi, rsm_config = configs["gi"], configs["rsm"]
    if quality == "preview":
        vpls = max(1, rsm_config.vpl_samples // PREVIEW_VPL_DIVISOR)
        configs["rsm"] = dataclasses.replace(rsm_config, vpl_samples=vpls)
        configs["gi"] = dataclasses.replace(gi, sample_budget_px=0)
    width, height = view_size(region.width, region.height, gi.resolution, quality)
    camera = region_camera(*matrices, width, height, context.scene.unit_settings.scale_length)
    overlay = overlay_for(region_key, quality)
    # The passes bind other framebuffers; leaving them does not always rebind the one Blender drew into
    # (an offscreen's bind() restores the window's), so remember it and bind it again to present.
    framebuffer, region_viewport = gpu.state.active_framebuffer_get(), gpu.state.viewport_get()
    with _restored_gpu_state():
        t0 = time.perf_counter()
        computed = overlay.update(state, camera, configs)
        # Nothing changed: one more gather averaged in while the view is still (progressive refinement),
        # and another redraw asked for until MAX_SAMPLES.
        refined = False
        if not computed and quality == "full" and overlay.method.samples < MAX_SAMPLES:
            before = overlay.method.samples
            overlay.method.refine()  # nothing where the method has no noisy product or needs a solve
            refined = overlay.method.samples > before
        if computed or refined:
            backend().finish()  # one wait per update (not per pass), so the time shown is the GPU's too
    if computed or refined:
        gpu_runs += 1
        state.last_update_ms = (time.perf_counter() - t0) * 1e3  # uploads included
        samples = overlay.method.samples
        state.samples = samples
        state.info = (f"{gi.method}, {width} x {height} px ({quality}): {state.last_update_ms:.1f} ms"
                      + (f", {samples} sample(s)" if overlay.method.NOISY else ""))
    # Ask for the next refinement only after progress: a method that cannot refine (its light field not
    # kept) would otherwise redraw forever.
    if (computed or refined) and overlay.method.NOISY and quality == "full" and overlay.method.samples < MAX_SAMPLES:
        live.redraw_soon()
    view_mode, state.note = shown_view(overlay.method, settings.view_mode)
    with _restored_gpu_state(), framebuffer.bind():
        gpu.state.viewport_set(*region_viewport)
        present(overlay.method, view_mode, settings.exposure, settings.strength)


# ----------------------------------------------------------------------------------------- registration

def register() -> None:
    global _handle
    if _handle is None:
        _handle = bpy.types.SpaceView3D.draw_handler_add(draw_callback, (), "WINDOW", "POST_VIEW")


def unregister() -> None:
    global _handle, _backend, _present_batch
    if _handle is not None:
        bpy.types.SpaceView3D.draw_handler_remove(_handle, "WINDOW")
        _handle = None
    # Free the GPU textures and programs: a re-enabled add-on starts from scratch.
    _overlays.clear()
    _views.clear()
    _backend = _present_batch = None
