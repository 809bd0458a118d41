"""Method `direct`: RSM-shadowed direct diffuse light only -- the radiometry check against Cycles'
Diffuse Direct pass, and the base every indirect method adds to.

Passes: gbuffer -> for each light face: rsm -> direct_light. Geometry is uploaded once per scene
(`set_scene`); `run()` is one full update with lights and camera as they are now.
"""

from __future__ import annotations

import contextlib
from dataclasses import dataclass, field, replace

import numpy as np

from ..backends.base import Backend
from ..config import GIConfig, RsmConfig
from ..errors import ConfigError
from ..passes import direct_light, gbuffer, rsm, zero
from ..passes.light_views import LightView, emissive_lights, views_for
from ..scene import Camera, Scene


@dataclass
class Result:
    """Images in image order (row 0 = top), float32 (h, w, 4); alpha = geometry coverage."""

    images: dict[str, np.ndarray]
    timings_ms: dict[str, float] = field(default_factory=dict)


def triangle_attributes(scene: Scene, select: np.ndarray | None = None) -> dict[str, np.ndarray] | None:
    """Per-vertex arrays for the raster passes: three vertices per triangle, flat albedo and glossy lobe
    (specular: F0, roughness); `select` picks triangles (None: all). None when nothing is left to draw."""
    sel = np.ones(scene.triangle_count, bool) if select is None else select
    n = int(sel.sum())
    if n == 0:
        return None
    return {
        "pos_ws": scene.positions_m[sel].reshape(n * 3, 3).astype(np.float32),
        "normal_ws": scene.normals[sel].reshape(n * 3, 3).astype(np.float32),
        "albedo": np.repeat(scene.albedo[sel].astype(np.float32), 3, axis=0),
        "specular": np.repeat(np.c_[scene.specular_f0()[sel], scene.glossy_roughness()[sel]], 3, axis=0),
    }


class DirectMethod:
    name = "direct"
    products = ("direct", "albedo")

    def __init__(self, backend: Backend, gi: GIConfig, rsm_config: RsmConfig):
        self.backend, self.gi, self.rsm_config = backend, gi, rsm_config
        self.source: Scene | None = None  # the caller's scene: camera and lights are read from it per update
        self.scene: Scene | None = None  # its geometry as uploaded (re-centred, sanitised)
        self._meshes: dict[str, object] = {}
        self._size: tuple[int, int] | None = None
        # Per-pass timings wait for the GPU around every pass: right for benchmarks, a stall per pass
        # in an interactive viewport, which turns it off and times the whole update itself.
        self.profile = True

    def timed(self, timings: dict[str, float], name: str):
        """Time a block into timings[name] when profiling; otherwise run it untimed (no GPU sync)."""
        return self.backend.timed(timings, name) if self.profile else contextlib.nullcontext()

    def set_scene(self, scene: Scene) -> None:
        """Upload geometry once; call again only when geometry changes. Camera and lights may change
        between updates without it: set_camera / set_lights, or by changing `scene`'s own fields."""
        if scene.camera is None:
            raise ValueError("DirectMethod needs a scene with a camera")
        be = self.backend
        self.source = scene
        self.scene, self.origin_m = scene.prepared()
        # Emissive meshes light the scene like lamps (already in the uploaded, re-centred frame).
        # Bounds reduce over every vertex (10-14 ms for Sponza's 200k): once per geometry change, not per update.
        self.bounds_m = self.scene.bounds_m()
        lo, hi = self.bounds_m
        self.emissive = emissive_lights(self.scene.positions_m, self.scene.emission, float((hi - lo).max()))
        # Emitters stay out of the RSMs: their lamps sit on or inside them (a sphere's lamp at its centre
        # would be shadowed by the sphere itself). They then cast no shadow for other lights either.
        not_emitting = ~np.any(self.scene.emission > 0, axis=1)
        selections = {gbuffer.SPEC: self.scene.seen_by_camera(), rsm.SPEC: not_emitting}
        self._meshes = {}
        for spec, select in selections.items():
            attrs = triangle_attributes(self.scene, select)
            self._meshes[spec.name] = be.mesh(be.program(spec), attrs, "triangles") if attrs is not None else None
        n = self.rsm_config.resolution
        self.rsm = {k: be.texture((n, n)) for k in ("position", "normal", "flux")}
        self.rsm_target = be.target([self.rsm["position"], self.rsm["normal"], self.rsm["flux"]],
                                    be.depth_texture((n, n)))
        self._size = None
        self._allocate_images()

    def set_camera(self, camera: Camera) -> None:
        self.source = replace(self.source, camera=camera)
        self._allocate_images()

    def set_lights(self, lights: list) -> None:
        self.source = replace(self.source, lights=list(lights))

    def _allocate_images(self) -> None:
        """Camera-sized targets, (re)made only when the camera's size changes."""
        size = (self.source.camera.width, self.source.camera.height)
        if size == self._size:
            return
        be = self.backend
        self._size = size
        self.gbuf = {k: be.texture(size) for k in gbuffer.CHANNELS}
        self.gbuf_target = be.target([self.gbuf[k] for k in gbuffer.CHANNELS], be.depth_texture(size))
        self.allocate_products(size)

    def allocate_products(self, size: tuple[int, int]) -> None:
        self.direct = self.backend.texture(size)

    def camera(self) -> Camera:
        """The current camera in the uploaded geometry's (re-centred) frame."""
        cam = self.source.camera
        shift = np.eye(4)
        shift[:3, 3] = self.origin_m
        return replace(cam, view=cam.view @ shift)

    def light_views(self) -> list[LightView]:
        bounds = self.bounds_m
        lights = [replace(light, position_m=light.position_m - self.origin_m) for light in self.source.lights]
        lights += self.emissive
        return [v for i, light in enumerate(lights) for v in views_for(light, i, bounds, self.rsm_config.resolution)]

    def compute(self, run_gbuffer: bool = True) -> dict[str, float]:
        """Every pass of one update, no read-back (the viewport samples the textures); the G-buffer may
        be skipped when only lights changed. Returns timings in ms per pass."""
        be = self.backend
        self._allocate_images()
        timings: dict[str, float] = {}
        with self.timed(timings, "total"):
            if run_gbuffer:
                with self.timed(timings, "gbuffer"):
                    gbuffer.run(be, self.gbuf_target, self.gbuf, self._meshes[gbuffer.SPEC.name], self.camera())
            self.clear_products()
            for view in self.light_views():
                with self.timed(timings, "rsm"):
                    rsm.run(be, self.rsm_target, self._meshes[rsm.SPEC.name], view)
                with self.timed(timings, "direct_light"):
                    direct_light.run(be, self.gbuf["position"], self.gbuf["normal"], self.rsm["position"],
                                     self.direct, view, self.rsm_config.shadow_bias_texels)
                self.per_light_view(view, timings)
        return timings

    def read(self) -> dict[str, np.ndarray]:
        """The products in image order (row 0 = top), alpha = geometry coverage."""
        albedo = self.backend.read(self.gbuf["albedo"])
        images = {"albedo": albedo}
        for name, tex in self.product_textures().items():
            images[name] = self.backend.read(tex)
            images[name][..., 3] = albedo[..., 3]
        return {k: np.ascontiguousarray(v[::-1]) for k, v in images.items()}

    def run(self) -> Result:
        """One full update (G-buffer, every light, read-back), timed: what a benchmark measures."""
        timings: dict[str, float] = {}
        with self.timed(timings, "total"):
            timings.update({k: v for k, v in self.compute().items() if k != "total"})
            with self.timed(timings, "readback"):
                images = self.read()
        return Result(images, timings)

    def clear_products(self) -> None:
        zero.images(self.backend, [self.direct])  # a compute pass: framebuffer clears are slow raster work

    def per_light_view(self, view: LightView, timings: dict[str, float]) -> None:
        """Hook for methods that add work per RSM face while it is bound (the indirect gathers)."""

    def product_textures(self) -> dict:
        return {"direct": self.direct}


class OneBounceMethod(DirectMethod):
    """Base of the indirect methods: the `indirect` product (Cycles' Diffuse Indirect units) beside
    direct light, allocated, cleared and read like `direct`. A method computes up to `max_bounces`
    diffuse bounces (GIConfig.bounces); more are refused."""

    products = ("direct", "indirect", "albedo")
    max_bounces = 1

    def __init__(self, backend: Backend, gi: GIConfig, rsm_config: RsmConfig):
        if gi.bounces > self.max_bounces:
            raise ConfigError(f"method {self.name} computes at most {self.max_bounces} bounce(s): "
                              f"GIConfig.bounces = {gi.bounces}")
        super().__init__(backend, gi, rsm_config)

    def allocate_products(self, size: tuple[int, int]) -> None:
        super().allocate_products(size)
        self.indirect = self.backend.texture(size)

    def clear_products(self) -> None:
        super().clear_products()
        zero.images(self.backend, [self.indirect])

    def product_textures(self) -> dict:
        return {**super().product_textures(), "indirect": self.indirect}
