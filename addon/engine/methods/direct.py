"""Method `direct`: RSM-shadowed direct diffuse light only -- the radiometry check against Cycles'
Diffuse Direct pass, and the base every indirect method adds to.

Passes: gbuffer -> for each light face: rsm -> direct_light. Geometry is uploaded once per scene
(`set_scene`); `run()` is one full update with lights and camera as they are now.

Every method's update has two halves (docs/ARCHITECTURE.md, "Light field and gathers"):
- the *solve*: geometry + lights -> a view-independent light field (the RSM of every light face, and
  what a method builds from them: the LPV's SH grid, the VCT's radiance pyramid);
- the *gather*: light field + a G-buffer (camera pixels or lightmap texels) -> direct, indirect, glossy.
`compute()` solves only when the lights or the geometry changed since the last solve (or the method
cannot keep its light field for this configuration, `keeps_light_field`); otherwise a camera move, or
the next object of a bake, only gathers. Hooks for subclasses: `begin_solve`, `solve_view` (per RSM
face, its RSM bound as `self.rsm`), `finish_solve`, `gather_view` (per face), `gather_pixels`.
"""

from __future__ import annotations

import contextlib
import dataclasses
from dataclasses import dataclass, field, replace

import numpy as np

from .. import registry, world
from ..area_light import emitter_table, split_area_light
from ..backends.base import Backend, ShaderSpec
from ..config import GIConfig, RsmConfig
from ..errors import ConfigError
from ..passes import (
    accumulate,
    albedo_atlas,
    atlas,
    declare,
    denoise,
    direct_light,
    gbuffer,
    rsm,
    sky_light,
    surface_support,
    zero,
)
from ..passes.light_views import KIND_CODE, LightView, emissive_lights, reaches, views_for
from ..scene import Camera, Scene

# Each light face's RSM is kept between updates while all of them fit in this budget, so a gather after
# a camera move reads them instead of redrawing them; a scene with more faces shares one RSM and solves
# at every update. 256 MB holds 75 faces at 256^2 texels (3 RGBA32F + depth: 52 bytes a texel).
RSM_KEEP_BYTES = 256 * 2**20
SEED_STRIDE = 1_000_003  # between the seeds of successive refinement gathers (a prime: no overlap pattern)
RSM_BYTES_PER_TEXEL = 3 * 16 + 4
# The fewest sky directions a world that lights at all gets: a quarter of the most it may get
# (RsmConfig.sky_directions for the camera: 64). Fewer regions are wider than the widest penumbra the
# sky pass filters (its MAX_SOFT_TEXELS), and the lit share of a clamped disc overstates a region's
# light through an opening: window-sky-sun's sky, a twelfth of its light beside the sun disc, got 22
# directions by its share; its floor away from the sun patch read 5-8x Cycles', direct rel_rmse_8
# 0.138 (bias 1.035); at 64, 0.082 (1.006); cornell-grey-world 0.046 -> 0.043 (128 px). The floor
# is lowered to keep its shadow draws within SKY_LEAST_TRIANGLE_DRAWS triangles, never below
# SKY_DIRECTIONS_LEAST: Sponza (67 k triangles, its grey world 2.5 % of its light) read 0.151 at 16
# and at 64 directions, whose draws took 527 ms against 135 (llvmpipe, one session).
SKY_DIRECTIONS_LEAST = 16
SKY_DIRECTIONS_LEAST_SHARE = 0.25
SKY_LEAST_TRIANGLE_DRAWS = 1_000_000


def sky_directions_least(triangles: int, most: int) -> int:
    """The fewest sky directions for a scene of `triangles` when `most` are allowed (above)."""
    affordable = SKY_LEAST_TRIANGLE_DRAWS // max(triangles, 1)
    wanted = min(int(most * SKY_DIRECTIONS_LEAST_SHARE), affordable)
    return min(most, max(SKY_DIRECTIONS_LEAST, wanted))


def world_key(scene: Scene) -> tuple:
    """Equal for equal worlds (colour and map)."""
    world_map = None if scene.world_map is None else (scene.world_map.shape, scene.world_map.tobytes())
    return np.asarray(scene.world_color, np.float32).tobytes(), world_map


def lights_key(lights) -> tuple:
    """Equal for equal light lists: what a light field was solved for (lights may be changed in place)."""
    def key(value):
        if isinstance(value, np.ndarray):
            return value.tobytes()
        return tuple(key(v) for v in value) if isinstance(value, tuple) else value

    return tuple(key(dataclasses.astuple(light)) for light in lights)


@dataclass
class Result:
    """Images in image order (row 0 = top), float32 (h, w, 4); alpha = geometry coverage."""

    images: dict[str, np.ndarray]
    timings_ms: dict[str, float] = field(default_factory=dict)


def face_planes(positions_m: np.ndarray, corner_normals: np.ndarray | None = None) -> np.ndarray:
    """(T, 4) float32: each triangle's unit normal and offset d (m; the plane n . x = d) of its fp32
    vertices, in float64; zeros for a degenerate triangle. The raster passes put their interpolated
    positions back on this plane (gbuffer.frag.glsl) and tell by its normal which side of the triangle
    they see (face_plane.glsl, face_side), as Cycles tells a back face. The normal points to the side
    of the winding or, given `corner_normals` (T, 3, 3), to the side those point to on average: the same
    side for a Blender mesh, whose corner normals follow its winding, and for a scene built with normals
    against its winding, the side its normals name."""
    p = np.asarray(positions_m, np.float32).astype(np.float64)
    normal = np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])
    if corner_normals is not None:
        against = np.einsum("ij,ij->i", normal, np.asarray(corner_normals, np.float64).sum(axis=1)) < 0
        normal[against] *= -1.0
    length = np.linalg.norm(normal, axis=1, keepdims=True)
    normal = np.divide(normal, length, out=np.zeros_like(normal), where=length > 0)
    return np.c_[normal, np.einsum("ij,ij->i", normal, p.mean(axis=1))].astype(np.float32)


def triangle_attributes(scene: Scene, spec: ShaderSpec, select: np.ndarray | None = None,
                        planes: np.ndarray | None = None, atlas: albedo_atlas.Atlas | None = None
                        ) -> dict[str, np.ndarray] | None:
    """Per-vertex arrays for raster pass `spec`, the attributes it declares only: three vertices per
    triangle, flat albedo (the camera's; bounce_albedo: toward other surfaces) and glossy lobe
    (specular: F0, roughness), the triangle's plane (`planes`: face_planes of all of `scene`'s
    triangles, made once per geometry change as they take 70-100 ms for 279 k; None: made here for the
    selection), the Base Color texture's place in `atlas` (albedo_atlas.triangle_attributes); `select`
    picks triangles (None: all). None when nothing is left."""
    sel = np.ones(scene.triangle_count, bool) if select is None else select
    n = int(sel.sum())
    if n == 0:
        return None
    build = {
        "pos_ws": lambda: scene.positions_m[sel].reshape(n * 3, 3).astype(np.float32),
        "plane_ws": lambda: np.repeat(face_planes(scene.positions_m[sel], scene.normals[sel])
                                      if planes is None else planes[sel], 3, axis=0),
        "normal_ws": lambda: scene.normals[sel].reshape(n * 3, 3).astype(np.float32),
        "albedo": lambda: np.repeat(scene.albedo[sel].astype(np.float32), 3, axis=0),
        "bounce_albedo": lambda: np.repeat(scene.bounce_reflectance()[sel], 3, axis=0),
        "specular": lambda: np.repeat(np.c_[scene.specular_f0()[sel], scene.glossy_roughness()[sel]], 3, axis=0),
    }
    names = [a.name for a in spec.attributes]
    textures = scene.albedo_textures
    if "albedo_rect" in names:
        build.update({name: (lambda array=array: array) for name, array in
                      albedo_atlas.triangle_attributes(textures, atlas, sel).items()})
        if textures is not None and atlas is not None:
            # A pass that samples the texture reads a textured triangle's albedo as its texels' factor.
            on = textures.index[sel] >= 0

            def factor(flat: np.ndarray, scale: np.ndarray) -> np.ndarray:
                out = np.asarray(flat[sel], np.float32).copy()
                out[on] = scale[sel][on]
                return np.repeat(out, 3, axis=0)

            build["albedo"] = lambda: factor(scene.albedo, textures.scale)
            build["bounce_albedo"] = lambda: factor(scene.bounce_reflectance(), textures.bounce_scale)
    return {name: build[name]() for name in names}


class DirectMethod:
    spec = registry.get("direct")
    name, products, max_bounces = spec.name, spec.products, spec.max_bounces

    # The passes of each half of an update (passes/declare.py), in the order they run: what the method
    # is, read as a list; tests check that it is what runs and that every input is written before.
    PASSES = {"setup": (), "camera": (gbuffer.DECL,), "solve": (rsm.DECL, sky_light.SHADOW_DECL, sky_light.BOUNDS_DECL),
              "gather": (sky_light.DIRECT_DECL, direct_light.DECL)}
    # Products of a stochastic gather, filtered after it when GIConfig.denoise (passes/denoise.py).
    NOISY: tuple[str, ...] = ()
    # Whether the world's bounce comes from its suns' RSMs (light_views): a method that takes the world's
    # light from the sky pass's directions instead (probes, gather, vct) draws none.
    WORLD_SUN_RSMS = True

    def __init_subclass__(cls, **kwargs):
        # A method's name, products and bounce limit are its registry entry's: declared once.
        super().__init_subclass__(**kwargs)
        if "spec" in cls.__dict__:
            cls.name, cls.products, cls.max_bounces = cls.spec.name, cls.spec.products, cls.spec.max_bounces

    def __init__(self, backend: Backend, gi: GIConfig, rsm_config: RsmConfig):
        self.backend, self.gi, self.rsm_config = backend, gi, rsm_config
        self.source: Scene | None = None  # the caller's scene: camera and lights are read from it per update
        self.scene: Scene | None = None  # its geometry as uploaded (re-centred, sanitised)
        self._meshes: dict[str, object] = {}
        self._size: tuple[int, int] | None = None
        # Per-pass timings wait for the GPU around every pass: right for benchmarks, a stall per pass
        # in an interactive viewport, which turns it off and times the whole update itself.
        self.profile = True
        self._atlas_images: list | None = None  # the images self.albedo_atlas was packed from
        self._atlas: albedo_atlas.Atlas | None = None

    def timed(self, timings: dict[str, float], name: str):
        """Time a block into timings[name] when profiling; otherwise run it untimed (no GPU sync)."""
        return self.backend.timed(timings, name) if self.profile else contextlib.nullcontext()

    def step(self, timings: dict[str, float], decl: declare.PassDecl):
        """Time a declared pass under its declared name (`timed`)."""
        return self.timed(timings, decl.name)

    def set_scene(self, scene: Scene) -> None:
        """Upload geometry once; call again only when geometry changes. Camera and lights may change
        between updates without it: set_camera / set_lights, or by changing `scene`'s own fields."""
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
        selections = {gbuffer.SPEC: self.scene.seen_by_camera(), rsm.SPEC: not_emitting,
                      sky_light.SHADOW_SPEC: not_emitting}
        # Every triangle's plane, once: the G-buffer's, the RSMs' and the probes' capture read it.
        self.planes = face_planes(self.scene.positions_m, self.scene.normals)
        atlas = self._albedo_atlas(self.scene.albedo_textures)
        self._meshes = {}
        for spec, select in selections.items():
            attrs = triangle_attributes(self.scene, spec, select, self.planes, atlas)
            self._meshes[spec.name] = be.mesh(be.program(spec), attrs, "triangles") if attrs is not None else None
        # The RSM's triangles by the index its texels name (rsm.frag.glsl): the direct pass's exact shadows.
        table = rsm.occluder_table(self.scene.positions_m[not_emitting])
        self.occluders = be.texture((table.shape[1], table.shape[0]), data=table)
        self._not_emitting = not_emitting
        self._bvh = None  # the same triangles' hierarchy (RsmConfig.sky_rays), made on first use
        n = self.rsm_config.resolution
        # (textures, target) per kept face and RSM size (LightView.resolution), made on use. Counted at
        # the largest size: a face's sizes, halved from it, add at most a third more.
        self._rsm_slots: dict[tuple[int, int], tuple[dict, object]] = {}
        self._kept_faces = max(1, RSM_KEEP_BYTES // (RSM_BYTES_PER_TEXEL * n * n))
        self.rsm, self.rsm_target = self._rsm_slot(0, n)  # the face being drawn or read (hooks use it)
        self._rsm_points: dict[tuple, object] = {}  # rsm_points' meshes
        self._slot = 0  # that face's slot: its sun shadow map's too
        self._sun_shadows: dict[int, tuple[dict, object]] = {}  # slot -> a sun's own shadow map (made on use)
        self._emitter_rows = None  # the emitter table on the GPU (light_views)
        self._world_key, self._world_suns = None, []
        self._world_map = None
        self._skies: dict[tuple, sky_light.SkyShadows] = {}  # sky(): per (most, least) directions asked for
        self.vpl_shares: dict[int, float] = {}
        self._solved_for = None  # lights_key of the light field on the GPU; None: none is
        self.solves = 0          # how many updates solved (bakes report it)
        # Whether the G-buffer holds a bake's texels (bake_raster.TexelBaker sets it): points of the
        # surfaces themselves, no depth test chose them, and each counts alike (exact_near_texels,
        # sky_light.AUTO_BAKE_WORLD_SHARE).
        self.baking = False
        self.support = None  # measure_support's image at the G-buffer's size, made on first use
        # The camera-sized images stay when the camera's size does (a geometry change rewrites them all;
        # at 1920 x 1080 re-making them cost ~200 ms of a geometry change); only the running average of
        # the noisy products restarts.
        self.samples = 0
        self._allocate_images()

    def _rsm_slot(self, index: int, texels: int) -> tuple[dict, object]:
        """The RSM textures and target of kept face `index` at `texels` a side, allocated on first use."""
        if (index, texels) not in self._rsm_slots:
            be, size = self.backend, (texels, texels)
            textures = {k: be.texture(size) for k in ("position", "normal", "flux")}
            target = be.target([textures["position"], textures["normal"], textures["flux"]], be.depth_texture(size))
            self._rsm_slots[index, texels] = (textures, target)
        return self._rsm_slots[index, texels]

    def rsm_points(self, texels: int | tuple[int, int], spec: ShaderSpec, copies: int = 1):
        """atlas.texel_points of an RSM `texels` a side (or (width, height)) for the splatting program
        `spec`, made once per size: the views' RSMs differ in size (LightView.resolution)."""
        key = (texels, spec.name, copies)
        if key not in self._rsm_points:
            self._rsm_points[key] = atlas.texel_points(self.backend, texels, spec, copies)
        return self._rsm_points[key]

    def _own_sun_shadow(self, view: LightView) -> bool:
        """Whether `view` (a sun lamp's face; world suns' direct light is the sky pass's) gets a shadow
        map of its own for its direct light (RsmConfig.sun_shadow_texels)."""
        return (self.rsm_config.sun_shadow_texels > 0 and view.uniforms["light_kind"] == KIND_CODE["SUN"]
                and view.light_index not in self.vpl_shares)

    def _albedo_atlas(self, textures) -> albedo_atlas.Atlas | None:
        """The atlas of `textures`' images (Scene.albedo_textures), uploaded as self.albedo_atlas. Packed
        again only when the images are other arrays than the last geometry change's: the capture keeps
        an image's texels while the image is unchanged, and a scene's textures can reach the atlas's
        128-256 MB, too much to pack and upload each time an object moves."""
        images = [] if textures is None else textures.images
        kept = self._atlas_images
        if kept is None or len(kept) != len(images) or any(a is not b for a, b in zip(kept, images, strict=True)):
            self._atlas = albedo_atlas.pack(images) if images else None
            self.albedo_atlas = albedo_atlas.upload(self.backend, self._atlas)
            self._atlas_images = list(images)  # held, so their ids cannot be reused by new arrays
        return self._atlas

    def _sun_shadow_slot(self, slot: int) -> tuple[dict, object]:
        if slot not in self._sun_shadows:
            be, n = self.backend, self.rsm_config.sun_shadow_texels
            textures = {k: be.texture((n, n)) for k in ("position", "normal", "flux")}
            target = be.target([textures["position"], textures["normal"], textures["flux"]], be.depth_texture((n, n)))
            self._sun_shadows[slot] = (textures, target)
        return self._sun_shadows[slot]

    def shadow_map(self, view: LightView) -> tuple[dict, LightView]:
        """What the direct pass tests `view`'s shadows against, and the view as that map's texels see it:
        the RSM's position, normal and flux textures, or a sun's own finer map's with its texel area scaled
        to match, and the occluder table the flux names triangles in."""
        if not self._own_sun_shadow(view):
            return {**{k: self.rsm[k] for k in ("position", "normal", "flux")}, "occluders": self.occluders}, view
        scale = (self.rsm_config.resolution / self.rsm_config.sun_shadow_texels) ** 2
        fine = replace(view, texel_scale=view.texel_scale * scale,
                       uniforms={**view.uniforms, "texel_scale": view.texel_scale * scale})
        textures = self._sun_shadow_slot(self._slot)[0]
        return {**{k: textures[k] for k in ("position", "normal", "flux")}, "occluders": self.occluders}, fine

    def set_camera(self, camera: Camera) -> None:
        self.source = replace(self.source, camera=camera)
        self._allocate_images()

    def set_lights(self, lights: list) -> None:
        self.source = replace(self.source, lights=list(lights))

    def set_world(self, world_color, world_map=None) -> None:
        """The world's light (Scene.world_color / world_map) for the next updates."""
        self.source = replace(self.source, world_color=np.asarray(world_color, np.float32), world_map=world_map)

    def world_suns(self) -> list:
        """The world as suns (world.py), recomputed only when the world changes."""
        key = world_key(self.source)
        if key != self._world_key:
            count = self.rsm_config.world_suns
            world_map = self.source.world_map
            if world_map is None and np.any(self.source.world_color > 0):
                world_map = world.constant_map(self.source.world_color)
            self._world_key = key
            self._world_map = world_map if count else None
            self._world_suns = world.world_suns(world_map, count) if count and world_map is not None else []
        return self._world_suns

    def sky(self, most: int | None = None, least: int | None = None) -> sky_light.SkyShadows | None:
        """The sky's directions (world.py's regions split by power x width) on the GPU, as many as the
        world's share of the scene's light asks (world.sky_direction_count), at most `most`
        (RsmConfig.sky_directions by default) and at least `least` (sky_directions_least by default);
        None without a world. Remade when the world or that count changes (the bounds change only with
        set_scene, which resets them)."""
        suns = self.world_suns()
        if not suns:
            return None
        most = self.rsm_config.sky_directions if most is None else most
        least = sky_directions_least(self.scene.triangle_count, most) if least is None else min(least, most)
        lo, hi = self.bounds_m
        lamps, radius_m = [*self.source.lights, *self.emissive], 0.5 * float(np.linalg.norm(hi - lo))
        count = world.sky_direction_count(suns, lamps, most, least, radius_m)
        rays = sky_light.rays_for(self.rsm_config.sky_rays, world.world_share(suns, lamps, radius_m),
                                  sky_light.AUTO_BAKE_WORLD_SHARE if self.baking else sky_light.AUTO_WORLD_SHARE)
        key = (self._world_key, count, rays)
        shadows = next((s for s in self._skies.values() if s.key == key), None)  # another call's: drawn once
        if shadows is None:
            shadows = self._skies.setdefault((most, least), sky_light.SkyShadows())
            suns, taps = world.sky_regions(self._world_map, count, rays)
            shadows.update(self.backend, key, suns, taps, self.bounds_m, self.rsm_config.sky_texels)
        return shadows if shadows.layout is not None else None

    def skies(self) -> list[sky_light.SkyShadows]:
        """Every set of sky directions an update shades with (the solve draws their shadow maps): the
        camera's."""
        sky = self.sky()
        return [sky] if sky is not None else []

    def light_key(self) -> tuple:
        """What a light field is solved for: the lights and the world."""
        return lights_key(self.source.lights), world_key(self.source)

    def _allocate_images(self) -> None:
        """Camera-sized targets, (re)made only when the camera's size changes; none without a camera
        (a solve alone needs none)."""
        if self.source.camera is None:
            return
        size = (self.source.camera.width, self.source.camera.height)
        if size == self._size:
            return
        be = self.backend
        self._size = size
        self.gbuf = declare.allocate(be, gbuffer.DECL.outputs, size)
        self.gbuf_target = be.target(list(self.gbuf.values()), be.depth_texture(size))
        self.allocate_products(size)

    def allocate_products(self, size: tuple[int, int]) -> None:
        """The products (registry), as their gather passes declare them, each also an attribute
        (`self.direct`, `self.indirect`, ...): the overlay and bakes sample them."""
        ports = {p.name: p for decl in self.PASSES["gather"] for p in decl.outputs if p.group == "product"}
        undeclared = [n for n in self.products if n != "albedo" and n not in ports]
        if undeclared:
            raise TypeError(f"method {self.name}: no gather pass in PASSES declares the product(s) {undeclared}")
        self._products = declare.allocate(self.backend, [ports[n] for n in self.products if n != "albedo"], size)
        for name, texture in self._products.items():
            setattr(self, name, texture)
        # Per noisy product (NOISY), three roles over its textures: `raw`, the gather's target; `mean`, the
        # average of this camera's gathers so far (the first gather's raw texture becomes it: no copy);
        # `shown` (+ scratch), the mean filtered when GIConfig.denoise. The attribute is what is shown.
        be = self.backend
        self._noisy = {n: {"raw": be.texture(size), "mean": self._products[n],
                           **({"shown": be.texture(size), "scratch": be.texture(size)} if self.gi.denoise else {})}
                       for n in self.NOISY}
        # What the filter's first iteration measures for the others (denoise.run's guide), for all products.
        self._denoise_guide = be.texture(size) if self.gi.denoise and self.NOISY else None
        self.samples = 0  # gathers averaged into the noisy products since the last update
        # The running gather's index among them: 0 for an update's, n for the n-th refine (gather_seed;
        # vct's cones continue a low-discrepancy sequence over it).
        self.sample_index = 0

    def camera(self) -> Camera:
        """The current camera in the uploaded geometry's (re-centred) frame."""
        cam = self.source.camera
        shift = np.eye(4)
        shift[:3, 3] = self.origin_m
        return replace(cam, view=cam.view @ shift)

    def light_views(self) -> list[LightView]:
        """Every light's RSM faces, in the uploaded (re-centred) frame; area lights split into patches.
        Also makes the emitter table of the lights with a shape (`self.emitters`), whose rows each
        view's uniforms name."""
        bounds = self.bounds_m
        lights = []
        for light in self.source.lights:
            local = replace(light, position_m=light.position_m - self.origin_m)
            if not reaches(local, bounds):
                continue  # only what the scene needs: a light that cannot reach the geometry has no view
            lights += split_area_light(local, self.rsm_config.area_patches) if local.kind == "AREA" else [local]
        lights += self.emissive
        # The world's suns share one light's VPL budget by power (vpl_shares: light index -> share): a
        # gather of vpl_samples per face of each of 32 suns made rsm ten times slower on Sponza. Their
        # RSMs are the world's bounce only (its direct light is the sky pass's, `sky`): a method without
        # indirect light draws none.
        suns = self.world_suns() if "indirect" in self.products and self.WORLD_SUN_RSMS else []
        self.vpl_shares = {len(lights) + i: float(p) for i, p in enumerate(world.power_shares(suns))}
        lights += suns
        table, ranges = emitter_table(lights)
        self._upload_emitters(table)
        views = []
        for i, light in enumerate(lights):
            for view in views_for(light, i, bounds, self.rsm_config.resolution):
                view.uniforms.update(poly_first=ranges[i][0], poly_count=ranges[i][1])
                views.append(view)
        return views

    def _upload_emitters(self, table: np.ndarray) -> None:
        """The emitter table as a texture (TABLE_TEXELS_PER_ROW x rows), re-uploaded only when it changes."""
        if self._emitter_rows is not None and np.array_equal(self._emitter_rows, table):
            return
        self._emitter_rows = table
        self.emitters = self.backend.texture((table.shape[1], table.shape[0]), data=table)

    def work(self) -> dict[str, int]:
        """Counts of what the last solve (and the bounces after it) did, for benchmarks: the method's own
        measure of work beside its times ({} when it has none; stats.json and results.json `work`)."""
        return {}

    def keeps_light_field(self) -> bool:
        """Whether the light field stays valid when only the camera or the G-buffer changes (methods
        whose solve depends on the camera, or whose gather consumes its light field, say no)."""
        return True

    def compute(self, run_gbuffer: bool = True, solve: bool | None = None) -> dict[str, float]:
        """Every pass of one update, no read-back (the viewport samples the textures); the G-buffer may
        be skipped when it is still valid (only lights changed, or a bake filled it). `solve`: None
        solves only when the lights or the geometry changed since the last solve; True always.
        Returns timings in ms per pass, and per half ("solve", "gather")."""
        if self.source.camera is None:
            raise ValueError(f"method {self.name}: an update needs a camera (set_camera); solve_light_field "
                             "needs none")
        self._allocate_images()
        views = self.light_views()
        keep = len(views) <= self._kept_faces
        key = self.light_key()
        if solve is None:
            solve = not (keep and self.keeps_light_field() and self._solved_for == key)
        timings: dict[str, float] = {}
        with self.timed(timings, "total"):
            if run_gbuffer:
                with self.step(timings, gbuffer.DECL):
                    gbuffer.run(self.backend, self.gbuf_target, self.gbuf, self._meshes[gbuffer.SPEC.name],
                                self.camera(), self.albedo_atlas)
            if keep:
                if solve:
                    with self.timed(timings, "solve"):
                        self._solve(views, timings, range(len(views)))
                with self.timed(timings, "gather"):
                    self._gather(views, timings, range(len(views)))
            else:  # one RSM for every face: each is drawn, solved and gathered in turn
                with self.timed(timings, "solve"):
                    self._draw_sky(timings)
                    self.begin_solve(timings)
                    self._bind_gather_targets()
                    self.clear_products()
                    self._sky_direct(timings)
                    for view in views:
                        self._draw_rsm(view, 0, timings)
                        self.solve_view(view, timings)
                        self._gather_view(view, timings)
                    self.finish_solve(timings)
                with self.timed(timings, "gather"):
                    self.gather_pixels(timings)
                    self._average_and_show(timings, first=True)
            self._solved_for = key if keep else None
            self.solves += 1 if solve or not keep else 0
        return timings

    def solve_light_field(self) -> dict[str, float]:
        """The solve alone, with no camera and no pixels (a volume bake); timings per pass."""
        views = self.light_views()
        keep = len(views) <= self._kept_faces
        timings: dict[str, float] = {}
        with self.timed(timings, "total"), self.timed(timings, "solve"):
            self._solve(views, timings, range(len(views)) if keep else [0] * len(views))
        self._solved_for = self.light_key() if keep else None
        self.solves += 1
        return timings

    def _draw_rsm(self, view: LightView, slot: int, timings: dict[str, float]) -> None:
        self.rsm, self.rsm_target = self._rsm_slot(slot, view.resolution)
        self._slot = slot
        with self.step(timings, rsm.DECL):
            rsm.run(self.backend, self.rsm_target, self._meshes[rsm.SPEC.name], view, self.albedo_atlas)
            if self._own_sun_shadow(view):  # the same orthographic view, finer
                rsm.run(self.backend, self._sun_shadow_slot(slot)[1], self._meshes[rsm.SPEC.name], view,
                        self.albedo_atlas)

    def _solve(self, views: list[LightView], timings: dict[str, float], slots) -> None:
        self._draw_sky(timings)
        self.begin_solve(timings)
        for view, slot in zip(views, slots, strict=True):
            self._draw_rsm(view, slot, timings)
            self.solve_view(view, timings)
        self.finish_solve(timings)

    def _draw_sky(self, timings: dict[str, float]) -> None:
        """Every sky direction's shadow map into its sky atlas (solve half); nothing without a world. A
        set of directions is drawn once: its maps change only with the geometry (set_scene makes new
        sets) or the directions (the world, or their count: a new key), not when a lamp moves."""
        for sky in self.skies():
            if sky.drawn_key == sky.key:
                continue
            sky.drawn_key = sky.key
            with self.step(timings, sky_light.SHADOW_DECL):
                sky_light.shadow(self.backend, sky.target, self._meshes[sky_light.SHADOW_SPEC.name], sky.layout,
                                 sky.views)
            with self.step(timings, sky_light.BOUNDS_DECL):
                sky_light.bounds(self.backend, sky.atlas, sky.bounds, sky.layout)

    def _sky_direct(self, timings: dict[str, float]) -> None:
        """The sky's direct light of every direction, in one pass, into `direct` (gather half)."""
        self.shade_sky(timings, sky_light.DIRECT_DECL, self.gbuf["position"], self.gbuf["normal"], self.direct)

    def exact_near_texels(self) -> float:
        """The exact shadow tests' margin for where the G-buffer's points come from (direct_light)."""
        return direct_light.SURFACE_NEAR_TEXELS if self.baking else direct_light.CAMERA_NEAR_TEXELS

    def shade_sky(self, timings: dict[str, float], decl, position, normal, out, accumulate: bool = True,
                  most: int | None = None, texel_lists=(None,), rays: bool = True) -> bool:
        """The sky's direct light (`sky(most)`) at the surfaces `position` / `normal` hold, into `out`
        (added, or replacing at those that hold one), timed as `decl`; False (nothing written) without a
        world. texel_lists: the texels to shade, as lists (probe_capture.texel_lists); None: every one.
        rays: shadows from exact rays where RsmConfig.sky_rays asks for them (sky_light.rays_for; else,
        and with False, the shadow maps' filter)."""
        sky = self.sky(most)
        if sky is None:
            return False
        count = sky.rays if rays else 0
        if count and self._bvh is None:  # made on first use: only exact rays need it
            self._bvh = sky_light.BvhTextures.upload(self.backend, self.scene.positions_m[self._not_emitting])
        with self.step(timings, decl):
            diagonal_m = float(np.linalg.norm(self.bounds_m[1] - self.bounds_m[0]))
            for texel_list in texel_lists:
                sky_light.direct(self.backend, position, normal, sky.atlas, sky.bounds, sky.table, out, sky.layout,
                                 diagonal_m, accumulate, texel_list, rays=count, tree=self._bvh,
                                 exact_near_texels=self.exact_near_texels())
        return True

    def _gather(self, views: list[LightView], timings: dict[str, float], slots, first: bool = True) -> None:
        self._bind_gather_targets()
        self.clear_products()
        self.begin_gather(timings)
        self._sky_direct(timings)
        for view, slot in zip(views, slots, strict=True):
            self.rsm, self.rsm_target = self._rsm_slot(slot, view.resolution)
            self._slot = slot
            self._gather_view(view, timings)
        self.gather_pixels(timings)
        self._average_and_show(timings, first)

    def begin_gather(self, timings: dict[str, float]) -> None:
        """Hook: before a gather's light views, what they all read of the G-buffer (rsm and vct: its
        surface support, measure_support). Nothing here."""

    def measure_support(self, timings: dict[str, float]) -> None:
        """`support`: how much of the denoise kernel lies on each pixel's own surface
        (passes/surface_support.py), where the stochastic gathers take more samples. Measured on an
        update's gather; the refinement gathers that follow keep the G-buffer, hence it."""
        size = self.gbuf["position"].size
        if self.support is not None and self.support.size == size and self.sample_index > 0:
            return
        if self.support is None or self.support.size != size:
            self.support = self.backend.texture(size, surface_support.SUPPORT.format)
        with self.step(timings, surface_support.DECL):
            surface_support.run(self.backend, self.gbuf, self.support)

    def _bind_gather_targets(self) -> None:
        """The noisy products' attributes point at their raw textures while a gather writes them."""
        for name, roles in self._noisy.items():
            setattr(self, name, roles["raw"])

    def _average_and_show(self, timings: dict[str, float], first: bool) -> None:
        """After a gather: the first one's raw texture becomes the mean (roles swap), a later one is
        averaged in (accumulate); the mean is filtered into `shown` (GIConfig.denoise) and shown."""
        self.samples = 1 if first else self.samples + 1
        iterations = denoise.iterations_for(max(self.gbuf["position"].size))
        for roles in self._noisy.values():
            if first:
                roles["raw"], roles["mean"] = roles["mean"], roles["raw"]
            else:
                with self.step(timings, accumulate.DECL):
                    accumulate.run(self.backend, roles["raw"], roles["mean"], 1.0 / self.samples)
        filtered = [name for name in self._noisy if self.gi.denoise and not self.known_zero(name)]
        if filtered:
            # All noisy products in the same dispatches: their G-buffer weights are computed once.
            roles = [self._noisy[name] for name in filtered]
            with self.step(timings, denoise.DECL):
                denoise.run(self.backend, self.gbuf, [r["mean"] for r in roles], [r["shown"] for r in roles],
                            [r["scratch"] for r in roles], denoise.Params(iterations=iterations),
                            guide=self._denoise_guide)
        for name, roles in self._noisy.items():
            shown = roles["shown" if name in filtered else "mean"]
            self._products[name] = shown
            setattr(self, name, shown)

    def known_zero(self, product: str) -> bool:
        """Whether `product` is 0 at every pixel for the current scene, so that filtering it is wasted
        work (vct's glossy light without glossy materials)."""
        return False

    def refine(self) -> dict[str, float]:
        """One more gather of the noisy products, the next sample (`sample_index`), averaged into them:
        progressive refinement while nothing changes (the light field, the G-buffer and the camera are kept). Returns
        timings (empty when not profiling); `samples` grows only when a gather ran: not for a method
        without noisy products, nor when the last update could not keep its light field (a gather then
        needs a solve first)."""
        if not self._noisy or self._solved_for is None or self._solved_for != self.light_key():
            return {}
        views = self.light_views()
        self.sample_index = self.samples
        timings: dict[str, float] = {}
        try:
            with self.timed(timings, "total"), self.timed(timings, "gather"):
                self._gather(views, timings, range(len(views)), first=False)
        finally:
            self.sample_index = 0
        return timings

    def gather_seed(self) -> int:
        """The seed of the running gather's random numbers: GIConfig.seed for an update's gather, then
        SEED_STRIDE further per refine, far apart so that no sample's seeds (seed + 6 x light + face in
        the rsm gather) meet another's."""
        return (self.gi.seed + SEED_STRIDE * self.sample_index) % 2**31

    def _gather_view(self, view: LightView, timings: dict[str, float]) -> None:
        if view.light_index in self.vpl_shares:  # a world sun: its direct light is the sky pass's
            self.gather_view(view, timings)
            return
        with self.step(timings, direct_light.DECL):
            shadow, shadow_view = self.shadow_map(view)
            direct_light.run(self.backend, self.gbuf["position"], self.gbuf["normal"], shadow, self.direct,
                             shadow_view, self.rsm_config.shadow_bias_texels, self.emitters,
                             exact_near_texels=self.exact_near_texels())
        self.gather_view(view, timings)

    def read(self) -> dict[str, np.ndarray]:
        """The products in image order (row 0 = top), alpha = geometry coverage."""
        albedo = self.backend.read(self.gbuf["albedo"])
        images = {"albedo": albedo}
        for name, tex in self.product_textures().items():
            images[name] = self.backend.read(tex)
            images[name][..., 3] = albedo[..., 3]
        return {k: np.ascontiguousarray(v[::-1]) for k, v in images.items()}

    def run(self) -> Result:
        """One full update (G-buffer, every light and the world's sky, read-back), timed: what a
        benchmark measures. What solves keep across lamp moves is redone too (forget_kept_light)."""
        self.forget_kept_light()
        timings: dict[str, float] = {}
        with self.timed(timings, "total"):
            timings.update({k: v for k, v in self.compute(solve=True).items() if k != "total"})
            with self.timed(timings, "readback"):
                images = self.read()
        return Result(images, timings)

    def forget_kept_light(self) -> None:
        """Drop the light work a solve keeps while only lamps move (the sky's shadow maps, _draw_sky),
        so that the next solve does all of it again."""
        for sky in self._skies.values():
            sky.drawn_key = None

    def clear_products(self) -> None:
        zero.images(self.backend, [self.direct])  # a compute pass: framebuffer clears are slow raster work

    # Hooks of the two halves (module docstring); `direct` has nothing beyond its RSMs and direct light.
    def begin_solve(self, timings: dict[str, float]) -> None:
        """Before the first face's RSM: clear what the solve accumulates into."""

    def solve_view(self, view: LightView, timings: dict[str, float]) -> None:
        """Per RSM face (`self.rsm`), view-independent work: injection into the light field."""

    def finish_solve(self, timings: dict[str, float]) -> None:
        """After every face: complete the light field (propagation, pyramids, bounces)."""

    def gather_view(self, view: LightView, timings: dict[str, float]) -> None:
        """Per RSM face (`self.rsm`), after its direct light: per-pixel work that reads the face."""

    def gather_pixels(self, timings: dict[str, float]) -> None:
        """After every face's gather: per-pixel reads of the light field (lookups, cones)."""

    def product_textures(self) -> dict:
        return dict(self._products)


class OneBounceMethod(DirectMethod):
    """Base of the indirect methods: the `indirect` product (Cycles' Diffuse Indirect units) beside
    direct light, allocated, cleared and read like `direct`. A method computes up to `max_bounces`
    diffuse bounces (GIConfig.bounces); more are refused."""

    def __init__(self, backend: Backend, gi: GIConfig, rsm_config: RsmConfig):
        if gi.bounces > self.max_bounces:
            raise ConfigError(f"method {self.name} computes at most {self.max_bounces} bounce(s): "
                              f"GIConfig.bounces = {gi.bounces}")
        super().__init__(backend, gi, rsm_config)

    def clear_products(self) -> None:
        super().clear_products()
        zero.images(self.backend, [self.indirect])
