"""The Scene the pipeline consumes: numpy arrays in world space, metres, Cycles' light units.

Built from Blender by addon/bridge/capture.py, or by hand in tests. Triangles are flat arrays so a
pass uploads them once; per-triangle material values keep grids and VPLs cheap (bakes sample textures
per texel separately).
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

LIGHT_KINDS = ("POINT", "SPOT", "SUN", "AREA")
AREA_SHAPES = ("SQUARE", "RECTANGLE", "DISK", "ELLIPSE")


@dataclass
class Light:
    """A lamp, in Cycles' units.

    POINT/SPOT: radiant intensity power_w / (4 pi) * color W/sr (a spot masks it by its cone);
    SUN: irradiance strength * color W/m^2 on a surface facing it; AREA: one-sided Lambertian emitter of
    total power power_w (radiance power_w / (area * pi)). `direction` is where the light points (its -Z).
    """

    kind: str
    position_m: np.ndarray
    direction: np.ndarray
    color: np.ndarray
    power_w: float = 0.0
    spot_size_rad: float = np.pi
    spot_blend: float = 0.0
    sun_strength: float = 0.0
    sun_angle_rad: float = 0.0
    area_shape: str = "SQUARE"
    size_x_m: float = 0.0
    size_y_m: float = 0.0
    axis_x: np.ndarray = field(default_factory=lambda: np.array([1.0, 0.0, 0.0]))  # area light's local X
    name: str = ""
    # An opaque disc of this radius at position_m facing `direction`: the emitter's own surface (emissive
    # meshes, light_views.emissive_lights). Light the RSM's surfels reflect back towards it does not pass
    # it (rsm.frag.glsl: their flux times 1 - the disc's view factor); 0 = none.
    occluder_radius_m: float = 0.0
    # The light's shape as polygons (area_light.Emitter): the direct pass integrates it exactly and
    # position_m is only where its shadow is taken from. None: a point (or Lambertian point) emitter.
    emitter: Any = None

    def __post_init__(self):
        if self.kind not in LIGHT_KINDS:
            raise ValueError(f"light kind {self.kind!r} not in {LIGHT_KINDS}")
        self.position_m = np.asarray(self.position_m, np.float64)
        d = np.asarray(self.direction, np.float64)
        self.direction = d / max(np.linalg.norm(d), 1e-30)
        self.color = np.asarray(self.color, np.float64)


@dataclass
class Camera:
    """World -> view (4x4) and an OpenGL-style projection (4x4), numpy row-major; image size in pixels."""

    view: np.ndarray
    projection: np.ndarray
    width: int
    height: int

    @property
    def view_projection(self) -> np.ndarray:
        return self.projection @ self.view

    @property
    def position_m(self) -> np.ndarray:
        return np.linalg.inv(self.view)[:3, 3]


def first_copies(positions_m: np.ndarray) -> np.ndarray:
    """(n,) bool: True for each triangle that is the first with its three corners (in any order and
    winding; the positions compared bit for bit). A renderer that shades both sides draws a surface
    once however often it is repeated, while summed voxel areas would count every copy: the voxelizer's
    opacity changed by up to 19 % for a duplicated room (tests/hard/test_degenerate.py)."""
    n = len(positions_m)
    if n == 0:
        return np.ones(0, bool)
    corners = np.ascontiguousarray(positions_m, np.float64)
    order = np.lexsort(corners.transpose(2, 0, 1)[::-1], axis=-1)  # per triangle, corners sorted by x, y, z
    canonical = np.ascontiguousarray(np.take_along_axis(corners, order[..., None], axis=1).reshape(n, 9))
    keys = canonical.view(np.dtype((np.void, canonical.dtype.itemsize * 9))).ravel()
    _, first = np.unique(keys, return_index=True)
    out = np.zeros(n, bool)
    out[first] = True
    return out


@dataclass
class AlbedoTextures:
    """Base Color image textures read per pixel: by the camera's G-buffer and the RSMs (the VPLs' flux).
    The voxels and the probes keep the per-triangle albedos (`Scene.albedo`, `bounce_albedo`: the
    texture's mean over the triangle), as they average light over far more than a texel.

    `images[k]` (h, w, 3) float32 linear RGB, row 0 = v 0 (Blender's order); `nearest[k]`: Closest
    interpolation (else bilinear, Cycles' Linear), `clamp[k]`: Extend (else Repeat). Per triangle:
    `index` (n,) int32, -1 where the albedo is flat; `uv` (n, 3, 2) float32 corner UVs; `scale` (n, 3)
    float32, the camera's albedo at a point is clip(texel x scale, 0, 1) (the material's other factors
    over the texture: `Scene.albedo` is the same product averaged over the triangle); `bounce_scale`
    the same for the albedo toward other surfaces (`Scene.bounce_albedo`), which the RSMs read per
    texel."""

    images: list[np.ndarray]
    nearest: list[bool]
    clamp: list[bool]
    index: np.ndarray
    uv: np.ndarray
    scale: np.ndarray
    bounce_scale: np.ndarray

    def subset(self, keep: np.ndarray) -> AlbedoTextures:
        return replace(self, index=self.index[keep], uv=self.uv[keep], scale=self.scale[keep],
                       bounce_scale=self.bounce_scale[keep])


@dataclass
class Scene:
    """Triangles (n, 3 corners, 3) with per-corner normals, per-triangle diffuse albedo and emitted
    radiance (W/m^2/sr, emission colour x strength), lights, the world (a constant radiance
    `world_color`, or an equirectangular radiance map `world_map` in world.py's layout that then
    replaces it) and the camera. Empty scenes are valid: zero triangles, zero lights.

    The glossy lobe (optional, None = none): per triangle `specular` (n, 3), the GGX lobe's reflectance
    at normal incidence F0 (metals: their base colour; dielectrics ((ior - 1) / (ior + 1))^2 x 2 x
    Specular IOR Level), and `roughness` (n,), Blender's Roughness (GGX alpha = roughness^2).

    `albedo` is what the camera sees (Cycles' Diffuse Color pass); `bounce_albedo` (n, 3, optional, None =
    `albedo`) is how a surface reflects light toward another diffuse surface (a path's vertex after a
    diffuse bounce), which the emitters of every indirect method use. They differ under a glossy layer:
    there Cycles drops Principled BSDF's specular layer (reflective caustics off, as the reference
    renders) and with it the layer's attenuation of the diffuse lobe, so the surface reflects its full
    base colour (with caustics on, the layer reflects about what it takes from the diffuse lobe)."""

    positions_m: np.ndarray = field(default_factory=lambda: np.zeros((0, 3, 3), np.float32))
    normals: np.ndarray = field(default_factory=lambda: np.zeros((0, 3, 3), np.float32))
    albedo: np.ndarray = field(default_factory=lambda: np.zeros((0, 3), np.float32))
    emission: np.ndarray = field(default_factory=lambda: np.zeros((0, 3), np.float32))
    lights: list[Light] = field(default_factory=list)
    world_color: np.ndarray = field(default_factory=lambda: np.zeros(3, np.float32))
    world_map: np.ndarray | None = None
    camera: Camera | None = None
    warnings: list[str] = field(default_factory=list)
    # Per triangle: False where the object is hidden from the camera but still reflects light (the
    # G-buffer skips it, the RSMs keep it). None means every triangle is visible.
    camera_visible: np.ndarray | None = None
    specular: np.ndarray | None = None
    roughness: np.ndarray | None = None
    bounce_albedo: np.ndarray | None = None
    albedo_textures: AlbedoTextures | None = None  # None: every triangle's albedo is flat

    def bounce_reflectance(self) -> np.ndarray:
        """(n, 3) float32 albedo toward other diffuse surfaces (see the class): `albedo` where None."""
        return np.asarray(self.albedo if self.bounce_albedo is None else self.bounce_albedo, np.float32)

    def specular_f0(self) -> np.ndarray:
        """(n, 3) float32 F0 of every triangle's glossy lobe; zeros when the scene has none."""
        if self.specular is None:
            return np.zeros((self.triangle_count, 3), np.float32)
        return np.asarray(self.specular, np.float32)

    def glossy_roughness(self) -> np.ndarray:
        """(n,) float32 roughness in [0, 1]; 1 (the widest lobe) when the scene gives none."""
        if self.roughness is None:
            return np.ones(self.triangle_count, np.float32)
        return np.asarray(self.roughness, np.float32)

    def seen_by_camera(self) -> np.ndarray:
        if self.camera_visible is None:
            return np.ones(self.triangle_count, bool)
        return np.asarray(self.camera_visible, bool)

    def has_light_source(self) -> bool:
        """Whether anything lights the scene: a light with power (or a sun with strength) and a colour, an
        emissive triangle, or a world that is not black."""
        def emits(light: Light) -> bool:
            strength = light.sun_strength if light.kind == "SUN" else light.power_w
            return strength > 0 and bool(np.any(np.asarray(light.color) > 0))

        world_lit = np.any(self.world_color > 0) or (self.world_map is not None and np.any(self.world_map > 0))
        return any(emits(light) for light in self.lights) or bool(np.any(self.emission > 0)) or bool(world_lit)

    @property
    def triangle_count(self) -> int:
        return int(self.positions_m.shape[0])

    def prepared(self) -> tuple[Scene, np.ndarray]:
        """The geometry as the GPU passes want it, and the world position of its new origin.

        Triangles with a non-finite corner or zero area are dropped (one warning), since one NaN corner
        would poison the bounds every light view is fitted to. Positions are re-centred on the bounds'
        centre in float64 before the passes convert them to float32: 1e5 m from the origin fp32 keeps
        only ~8 mm, less than a shadow map's bias. Images do not depend on the origin.
        """
        pos = np.asarray(self.positions_m, np.float64)
        finite = np.all(np.isfinite(pos), axis=(1, 2)) & np.all(np.isfinite(self.normals), axis=(1, 2))
        area2 = np.zeros(len(pos))
        edge2 = np.zeros(len(pos))
        e1, e2 = pos[finite, 1] - pos[finite, 0], pos[finite, 2] - pos[finite, 0]
        area2[finite] = np.linalg.norm(np.cross(e1, e2), axis=1)
        edge2[finite] = np.maximum((e1 * e1).sum(axis=1), (e2 * e2).sum(axis=1))
        # Zero area relative to the triangle's size: collinear float32 corners leave a ~1e-7 residue.
        keep = finite & (area2 > 1e-6 * edge2)
        warnings = list(self.warnings)
        if not np.all(keep):
            warnings.append(f"{int((~keep).sum())} triangles with non-finite corners or zero area were ignored")
        copies = keep & ~first_copies(pos)
        if np.any(copies):
            keep &= ~copies
            warnings.append(f"{int(copies.sum())} duplicated triangles (the same corners as another) were ignored")
        kept = replace(self, positions_m=pos[keep], normals=self.normals[keep], albedo=self.albedo[keep],
                       emission=self.emission[keep], warnings=warnings, camera_visible=self.seen_by_camera()[keep],
                       specular=self.specular_f0()[keep], roughness=self.glossy_roughness()[keep],
                       bounce_albedo=self.bounce_reflectance()[keep],
                       albedo_textures=None if self.albedo_textures is None else self.albedo_textures.subset(keep))
        lo, hi = kept.bounds_m()
        origin = (lo + hi) / 2.0
        # Geometry only: lights and camera stay in world space and are shifted per update by the method.
        local = replace(kept, positions_m=(kept.positions_m - origin).astype(np.float32), lights=[], camera=None)
        return local, origin

    def bounds_m(self) -> tuple[np.ndarray, np.ndarray]:
        """Axis-aligned bounds of the geometry; a unit box at the origin for an empty scene."""
        if self.triangle_count == 0:
            return np.full(3, -0.5), np.full(3, 0.5)
        pts = self.positions_m.reshape(-1, 3)
        return pts.min(axis=0).astype(np.float64), pts.max(axis=0).astype(np.float64)
