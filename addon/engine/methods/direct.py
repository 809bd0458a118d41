"""Method `direct`: RSM-shadowed direct diffuse light only -- the radiometry check against Cycles'
Diffuse Direct pass, and the base every indirect method adds to.

Passes: gbuffer -> for each light face: rsm -> direct_light. Geometry is uploaded once per scene
(`set_scene`); `run()` is one full update with lights and camera as they are now.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..backends.base import Backend
from ..config import GIConfig, RsmConfig
from ..passes import direct_light, gbuffer, rsm
from ..passes.light_views import LightView, views_for
from ..scene import Scene


@dataclass
class Result:
    """Images in image order (row 0 = top), float32 (h, w, 4); alpha = geometry coverage."""

    images: dict[str, np.ndarray]
    timings_ms: dict[str, float] = field(default_factory=dict)


def triangle_attributes(scene: Scene) -> dict[str, np.ndarray] | None:
    """Per-vertex arrays for the raster passes: three vertices per triangle, flat albedo."""
    if scene.triangle_count == 0:
        return None
    n = scene.triangle_count
    return {
        "pos_ws": scene.positions_m.reshape(n * 3, 3).astype(np.float32),
        "normal_ws": scene.normals.reshape(n * 3, 3).astype(np.float32),
        "albedo": np.repeat(scene.albedo.astype(np.float32), 3, axis=0),
    }


class DirectMethod:
    name = "direct"
    products = ("direct", "albedo")

    def __init__(self, backend: Backend, gi: GIConfig, rsm_config: RsmConfig):
        self.backend, self.gi, self.rsm_config = backend, gi, rsm_config
        self.scene: Scene | None = None
        self._meshes: dict[str, object] = {}

    def set_scene(self, scene: Scene) -> None:
        """Upload geometry and allocate every target once; call again only when geometry changes."""
        if scene.camera is None:
            raise ValueError("DirectMethod needs a scene with a camera")
        be = self.backend
        self.scene = scene
        attrs = triangle_attributes(scene)
        self._meshes = {
            spec.name: (be.mesh(be.program(spec), attrs, "triangles") if attrs is not None else None)
            for spec in (gbuffer.SPEC, rsm.SPEC)
        }
        w, h = scene.camera.width, scene.camera.height
        self.gbuf = {k: be.texture((w, h)) for k in ("position", "normal", "albedo")}
        self.gbuf_target = be.target([self.gbuf["position"], self.gbuf["normal"], self.gbuf["albedo"]],
                                     be.depth_texture((w, h)))
        n = self.rsm_config.resolution
        self.rsm = {k: be.texture((n, n)) for k in ("position", "normal", "flux")}
        self.rsm_target = be.target([self.rsm["position"], self.rsm["normal"], self.rsm["flux"]],
                                    be.depth_texture((n, n)))
        self.direct = be.texture((w, h))
        self._direct_target = be.target([self.direct])

    def light_views(self) -> list[LightView]:
        scene = self.scene
        bounds = scene.bounds_m()
        return [v for i, light in enumerate(scene.lights)
                for v in views_for(light, i, bounds, self.rsm_config.resolution)]

    def run(self) -> Result:
        be, scene = self.backend, self.scene
        timings: dict[str, float] = {}
        with be.timed(timings, "total"):
            with be.timed(timings, "gbuffer"):
                gbuffer.run(be, self.gbuf_target, self._meshes[gbuffer.SPEC.name], scene.camera)
            self.clear_products()
            for view in self.light_views():
                with be.timed(timings, "rsm"):
                    rsm.run(be, self.rsm_target, self._meshes[rsm.SPEC.name], view)
                with be.timed(timings, "direct_light"):
                    direct_light.run(be, self.gbuf["position"], self.gbuf["normal"], self.rsm["position"],
                                     self.direct, view, self.rsm_config.depth_bias_m)
                self.per_light_view(view, timings)
            with be.timed(timings, "readback"):
                albedo = be.read(self.gbuf["albedo"])  # alpha = coverage
                images = {"albedo": albedo}
                for name, tex in self.product_textures().items():
                    images[name] = be.read(tex)
                    images[name][..., 3] = albedo[..., 3]
        return Result({k: np.ascontiguousarray(v[::-1]) for k, v in images.items()}, timings)

    def clear_products(self) -> None:
        self.backend.clear(self._direct_target)

    def per_light_view(self, view: LightView, timings: dict[str, float]) -> None:
        """Hook for methods that add work per RSM face while it is bound (the indirect gathers)."""

    def product_textures(self) -> dict:
        return {"direct": self.direct}
