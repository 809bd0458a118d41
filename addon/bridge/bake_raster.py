"""Texel G-buffers for bakes, on any backend (no bpy here): a method's light passes shade texels.

`TexelBaker(method)` takes a method whose `set_scene` has run (the whole scene: RSMs, voxels) and, per
object, fills `method.gbuf` with the object's texels (passes/bake_gbuffer.py), runs
`method.compute(run_gbuffer=False)` and reads the products back: the first object's update solves the
light field, the others only gather from it. The camera only sets the G-buffer size.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from ..engine.passes import bake_gbuffer

POINTS_ROW = 256  # vertex-colour samples per G-buffer row


class TexelBaker:
    def __init__(self, method):
        if method.scene is None:
            raise ValueError("TexelBaker needs a method whose set_scene has run")
        self.method = method
        method.baking = True  # its G-buffer will hold the baked surfaces' own points
        self.backend = method.backend
        self._target = None
        self._target_key = None
        self._count_tex = None
        self.last_timings: dict[str, float] = {}  # the last shade's, per pass and half (solve, gather)

    def _resize(self, size: tuple[int, int]):
        m = self.method
        cam = m.source.camera
        if (cam.width, cam.height) != tuple(size):
            m.set_camera(replace(cam, width=int(size[0]), height=int(size[1])))
        key = id(m.gbuf["position"])
        if key != self._target_key:
            self._target = bake_gbuffer.target(self.backend, m.gbuf)
            self._target_key = key
        return self._target

    def _local(self, positions: np.ndarray) -> np.ndarray:
        """World metres -> the method's uploaded (re-centred) frame, in float64 before the fp32 upload."""
        return np.asarray(positions, np.float64) - self.method.origin_m

    def gbuffer(self, uv, positions, normals, albedo, size: tuple[int, int]) -> None:
        """Fill the method's G-buffer with the texels of triangles (n, 3, 2) uv, (n, 3, 3) world positions
        and corner normals, (n, 3) albedo, at `size` = (w, h) texels."""
        be = self.backend
        target = self._resize(size)
        mesh = None
        if len(uv):
            attrs = bake_gbuffer.triangle_attributes(np.asarray(uv, np.float64), self._local(positions), normals,
                                                     albedo)
            mesh = be.mesh(be.program(bake_gbuffer.SPEC), attrs, "triangles")
        bake_gbuffer.run(be, target, mesh, size)

    def overlap(self, uv, positions, normals, albedo, size: tuple[int, int]) -> float:
        """Fraction of covered texel centres that more than one triangle covers (overlapping UVs)."""
        be = self.backend
        if len(uv) == 0:
            return 0.0
        if self._count_tex is None or self._count_tex[0].size != tuple(size):
            self._count_tex = [be.texture(tuple(size)) for _ in range(3)]
            self._count_target = be.target(self._count_tex)
        attrs = bake_gbuffer.triangle_attributes(np.asarray(uv, np.float64), self._local(positions), normals, albedo)
        bake_gbuffer.count(be, self._count_target, be.mesh(be.program(bake_gbuffer.SPEC), attrs, "triangles"), size)
        c = be.read(self._count_tex[2])[..., 3]
        covered = int((c > 0.5).sum())
        return float((c > 1.5).sum()) / covered if covered else 0.0

    def shade(self) -> dict[str, np.ndarray]:
        """Run the light passes on the current G-buffer: images row 0 = top (V = 1), alpha = coverage;
        'direct', 'albedo' and, for indirect methods, 'indirect'."""
        # The light field is solved once per scene: later objects only gather (method.compute decides);
        # GIConfig.samples gathers are averaged (refine).
        self.last_timings = self.method.compute(run_gbuffer=False)
        for _ in range(self.method.gi.samples - 1):
            for key, ms in self.method.refine().items():
                self.last_timings[key] = self.last_timings.get(key, 0.0) + ms
        return self.method.read()

    def bake_triangles(self, uv, positions, normals, albedo, size: tuple[int, int]) -> dict[str, np.ndarray]:
        self.gbuffer(uv, positions, normals, albedo, size)
        return self.shade()

    def bake_points(self, positions, normals, albedo) -> dict[str, np.ndarray]:
        """Shade k samples (world positions and normals (k, 3), albedo (k, 3)): {product: (k, 4)}."""
        be = self.backend
        k = len(positions)
        size = (min(max(k, 1), POINTS_ROW), max(1, -(-k // POINTS_ROW)))
        target = self._resize(size)
        mesh = None
        if k:
            attrs = bake_gbuffer.point_attributes(k, size, self._local(positions), normals, albedo)
            mesh = be.mesh(be.program(bake_gbuffer.POINTS), attrs, "points")
        bake_gbuffer.run_points(be, target, mesh, size)
        images = self.shade()
        # read() gives row 0 = top; the samples were laid out from GL row 0 (the bottom).
        return {name: img[::-1].reshape(-1, img.shape[-1])[:k] for name, img in images.items()}
