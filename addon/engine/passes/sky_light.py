"""The sky's direct light (world.py's regions, many of them) from one atlas of small shadow maps and one
fused pass over the G-buffer.

Why: each world sun as its own RSM face and direct pass costs one G-buffer sweep per sun; a sky seen
through a window needs a hundred directions or more (docs/DIRECT.md). Sky shadows are soft, so each
direction's shadow map can be small: every direction is drawn into its tile of one atlas (the draw's
viewport, as the probe capture does), and one compute pass loops over the directions per pixel, the
G-buffer read once.

shadow (solve half): per direction, the scene (orthographic, fitted to the bounds as a sun's RSM)
drawn into tile k = (k % tiles_x, k // tiles_x) of `tile_texels`^2 texels; each texel holds the depth
along the direction's axis (m), w = 1 where geometry.
bounds (solve half): per block of BLOCK_TEXELS^2 texels, the least and greatest depth of the 3 x 3
blocks around it: a receiver in front of all of them is lit, behind all of them shadowed, in one fetch.
direct (gather half): per G-buffer pixel, sum over directions of E_k max(0, n . l_k) x the
percentage-closer soft-shadow visibility of its tile, / pi, added to `direct`; with RsmConfig.sky_rays,
the visibility is the share of the region's rays that cross no triangle (bvh.py, BvhTextures), tested
wherever the bounds do not show the receiver in front of everything (docs/DIRECT.md, "Exact rays").
The probes run it in their solve on their atlas G-buffer (probe_project.SKY_DECL), with a set of
directions of its own (SkyShadows), always with the filter.
The table (one row per direction, `TABLE_TEXELS` RGBA32F texels, then one per ray): the
view-projection's rows, the axis with the texel size (m), the irradiance normal to the axis (W/m^2 per
colour) with the tangent of the region's angular radius, then each ray's direction and share.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .. import bvh
from ..backends.base import Backend, Image, Sampler, ShaderSpec, Var, group_count
from ..scene import Light
from ..world import power_shares
from . import direct_light, rsm
from .declare import ALBEDO_ATLAS, BVH, DIRECT, GBUF_NORMAL, GBUF_POSITION, TRIANGLES, PassDecl, Port
from .light_views import views_for

TABLE_TEXELS = 6  # then RsmConfig.sky_rays texels of rays, when it asks for them
# Directions per dispatch of the direct pass with rays. llvmpipe caps the iterations of all the loops
# inside a shader's outermost loop together at 65535 and then leaves that loop: over 165 directions of 8
# rays each the hierarchy's steps passed it, and window-sky's floor summed only the first 71.
RAY_DIRECTIONS_PER_DISPATCH = 8

# RsmConfig.sky_rays = AUTO: exact rays where the world gives enough of the direct light that the
# filter's error on it shows. On window-sky (world share 0.74, `world.world_share`) the filter errs by
# 0.073 of the direct light, ~0.10 of the sky's own part; a sky that gives a share s of the light then
# adds ~0.10 s, past the direct light's 0.03 target from s = 0.3 (window-sky-sun, 0.09: 0.027 with the
# filter). 8 rays a region: window-sky 0.028 (docs/DIRECT.md, "Exact rays"). The viewport does not ask
# (bridge/viewport.py): the rays cost tens of times the filter's pass.
AUTO = -1
AUTO_RAYS = 8
AUTO_WORLD_SHARE = 0.3
# A bake's texels count every part of a surface alike, the parts a camera sees at a grazing angle or
# not at all included, and on them the filter errs several times more per unit of the world's share s:
# 0.3-3.2 s on the lightmaps measured (window-sky's Floor 2.37 and Ceiling 0.56 at s = 0.73,
# window-sky-sun's Ceiling 0.097 at 0.09, the grey-world box's BackWall 0.022 at 0.07), 0.1-0.3 s in
# their images. At ~1 x s it passes 0.03 from s = 0.03 (docs/BAKE.md). Sponza's grey world (0.024)
# keeps the filter.
AUTO_BAKE_WORLD_SHARE = 0.03


def rays_for(setting: int, share: float, least_share: float = AUTO_WORLD_SHARE) -> int:
    """Rays per sky region for RsmConfig.sky_rays = `setting` when the world gives `share` of the
    direct light: the setting itself, or for AUTO, AUTO_RAYS from `least_share` on (AUTO_WORLD_SHARE;
    a bake's AUTO_BAKE_WORLD_SHARE) and 0 (the filter) below."""
    if setting != AUTO:
        return setting
    return AUTO_RAYS if share >= least_share else 0


def viewport_rays(setting: int) -> int:
    """RsmConfig.sky_rays as the live viewport runs it: AUTO takes the filter there (it redraws on
    every change, and the rays cost tens of times its pass); a number set by hand, or by the High
    preset, is kept."""
    return 0 if setting == AUTO else setting


SHADOW_SPEC = ShaderSpec(
    name="sky_shadow",
    vertex="sky/shadow.vert.glsl",
    fragment="sky/shadow.frag.glsl",
    uniforms=(Var("light_view_projection", "mat4"), Var("emit_axis", "vec3")),
    attributes=(Var("pos_ws", "vec3"),),
    varyings=(Var("v_depth", "float"),),
    outputs=(Var("out_depth", "vec4"),),
)

# Texels per side of a block of the depth bounds, and the widest soft-shadow disc's radius in texels:
# one bounds fetch (the 3 x 3 blocks around the receiver's) covers every tap of its disc.
BLOCK_TEXELS = 8

BOUNDS_SPEC = ShaderSpec(
    name="sky_bounds",
    compute="sky/bounds.comp.glsl",
    local_size=(8, 8, 1),
    samplers=(Sampler("sky_depth_atlas", "2D"),),
    images=(Image("sky_bounds", "2D", "RGBA32F", "write"),),
    uniforms=(Var("tile_texels", "int"),),
    defines=(("BLOCK", str(BLOCK_TEXELS)),),
)

def _direct_spec(listed: bool, rays: bool) -> ShaderSpec:
    """listed: one invocation per texel of a list (`texel_list`, probe_capture.texel_lists) instead of
    per pixel: the probe atlas's texels that see geometry, so that the others cost no invocation.
    rays: each region's rays tested exactly against the triangles (bvh.py) instead of the shadow maps'
    soft-shadow filter."""
    return ShaderSpec(
        name="sky_direct" + ("_listed" if listed else "") + ("_rays" if rays else ""),
        compute="sky/direct.comp.glsl",
        local_size=(8, 8, 1),
        defines=(("BLOCK", str(BLOCK_TEXELS)),) + ((("TEXEL_LIST", "1"),) if listed else ())
        + ((("SKY_RAYS", "1"), ("NODE_ROW", str(bvh.NODE_ROW)), ("OCCLUDER_ROW", str(rsm.OCCLUDER_ROW)),
            ("LEAF_TRIANGLES", str(bvh.LEAF_TRIANGLES))) if rays else ()),
        samplers=(Sampler("gbuf_position", "2D"), Sampler("gbuf_normal", "2D"), Sampler("sky_depth_atlas", "2D"),
                  Sampler("sky_bounds", "2D"), Sampler("sky_table", "2D"))
        + ((Sampler("texel_list", "2D"),) if listed else ())
        + ((Sampler("bvh_nodes", "2D"), Sampler("bvh_triangles", "2D")) if rays else ()),
        images=(Image("direct", "2D", "RGBA32F", "read_write"),),
        uniforms=(Var("sky_count", "int"), Var("sky_first", "int"), Var("sky_chunk", "int"), Var("tiles_x", "int"),
                  Var("tile_texels", "int"), Var("scene_diagonal_m", "float"), Var("accumulate", "int"))
        + ((Var("sky_rays", "int"), Var("bvh_leaves", "int"), Var("exact_near_texels", "float")) if rays else ()),
    )


DIRECT_SPECS = {(listed, rays): _direct_spec(listed, rays) for listed in (False, True) for rays in (False, True)}

SKY_TABLE = Port("scene", "sky_table", "RGBA32F", "table",
                 "per sky direction: view-projection rows, axis and texel size (m), irradiance (W/m^2), its "
                 "region's rays (unit directions, shares of its light)")
SKY_DEPTH = Port("sky", "depth", "RGBA32F", "sky_atlas",
                 "per sky direction's tile: depth along its axis (m), w = 1 where geometry")

SKY_BOUNDS = Port("sky", "bounds", "RGBA32F", "sky_blocks",
                  "per block of BLOCK_TEXELS^2 atlas texels: least, greatest depth (m) over its 3 x 3 blocks")

SKY_RSM = (Port("sky", "rsm_position", "RGBA32F", "sky_atlas", "world position (m), w = 1 where geometry"),
           Port("sky", "rsm_normal", "RGBA32F", "sky_atlas",
                "world normal, facing the direction; w = surfel area (m^2) x the direction's power share"),
           Port("sky", "rsm_flux", "RGBA32F", "sky_atlas", "W reflected by the texel's surfel"))

SHADOW_DECL = PassDecl("sky_shadow", "solve", (TRIANGLES, SKY_TABLE), (SKY_DEPTH,),
                       "every sky direction's small shadow map, into its tile of one atlas")
BOUNDS_DECL = PassDecl("sky_bounds", "solve", (SKY_DEPTH,), (SKY_BOUNDS,),
                       "the atlas's depth bounds per block: most directions settled in one fetch")
RSM_DECL = PassDecl("sky_rsm", "solve", (TRIANGLES, ALBEDO_ATLAS, SKY_TABLE), SKY_RSM,
                    "every sky direction's RSM into its tile: the world's VPLs (vct)")
DIRECT_DECL = PassDecl("sky_direct", "gather", (GBUF_POSITION, GBUF_NORMAL, SKY_DEPTH, SKY_BOUNDS, SKY_TABLE, BVH),
                       (DIRECT,), "the sky's shadowed direct light of every direction, in one pass (with rays: "
                       "one pass per RAY_DIRECTIONS_PER_DISPATCH), added")


# The atlas's widest side: 64 MB of RGBA32F, and as much again per RSM tile texture vct adds. 1024 directions
# of the default 64 texels fill it; 189 directions of 1024 texels (RsmConfig.sky_texels' top) made a
# 14336-texel atlas of 3 GB that no framebuffer took.
ATLAS_MAX_TEXELS = 2048


@dataclass(frozen=True)
class SkyLayout:
    """The directions' tiles in the atlas: near square (tiles_x columns); tile_texels a multiple of
    BLOCK_TEXELS."""

    count: int
    tile_texels: int

    @classmethod
    def of(cls, count: int, texels: int) -> SkyLayout:
        """`count` tiles of `texels` per side rounded up to whole blocks, at most as many as keep the atlas
        within ATLAS_MAX_TEXELS a side (at least one block)."""
        fits = ATLAS_MAX_TEXELS // math.ceil(math.sqrt(count)) // BLOCK_TEXELS * BLOCK_TEXELS
        return cls(count, max(BLOCK_TEXELS, min(-(-texels // BLOCK_TEXELS) * BLOCK_TEXELS, fits)))

    @property
    def tiles_x(self) -> int:
        return math.ceil(math.sqrt(self.count))

    @property
    def size(self) -> tuple[int, int]:
        return self.tiles_x * self.tile_texels, math.ceil(self.count / self.tiles_x) * self.tile_texels

    @property
    def blocks(self) -> tuple[int, int]:
        return self.size[0] // BLOCK_TEXELS, self.size[1] // BLOCK_TEXELS

    def viewport(self, k: int) -> tuple[int, int, int, int]:
        n = self.tile_texels
        return (k % self.tiles_x) * n, (k // self.tiles_x) * n, n, n


class SkyShadows:
    """One set of sky directions on the GPU, as the passes need them: the table, the shadow atlas and its
    bounds, and each direction's view. Remade only when the directions change (`update`); the atlas
    (about 20 MB at 256 directions of 64^2 texels, outside the methods' RSM_KEEP_BYTES budget) only when
    their layout does."""

    def __init__(self):
        self.key = None  # what the directions were made from (the world and their count)
        self.drawn_key = None  # the key the shadow atlas was last drawn for (it holds until the key changes)
        self.layout: SkyLayout | None = None
        self.rays = 0  # rays per direction in the table (rays_for), 0: the filter
        self.rsm = None  # (textures, target) of the directions' RSM tiles, rsm_target()

    def update(self, backend: Backend, key, suns: list[Light], taps: np.ndarray,
               bounds: tuple[np.ndarray, np.ndarray], texels: int) -> None:
        """Make the table and draws of `suns` (their tiles `texels` a side) and their regions' rays `taps`
        (world.sky_regions; (len(suns), 0, 4) for none), remembered as `key`; no suns (a world whose
        regions all carry no light): no layout, nothing to draw."""
        self.rays = taps.shape[1]
        if not suns:
            self.layout, self.key = None, key
            return
        layout = SkyLayout.of(len(suns), texels)
        rows, self.views = table(suns, taps, bounds, layout.tile_texels)
        if layout != self.layout:
            self.atlas = backend.texture(layout.size)
            self.bounds = backend.texture(layout.blocks)
            self.target = backend.target([self.atlas], backend.depth_texture(layout.size))
            self.rsm = None  # rsm_target() makes them again at the new size
        self.table = backend.texture((rows.shape[1], rows.shape[0]), data=rows)
        self.layout, self.key = layout, key

    def rsm_target(self, backend: Backend) -> tuple[dict, object]:
        """The RSM tiles' textures (position, normal, flux; SKY_RSM) and their target, made on first use:
        only a method that injects the world's VPLs from them (vct) pays for them."""
        if self.rsm is None:
            size = self.layout.size
            textures = {k: backend.texture(size) for k in ("position", "normal", "flux")}
            self.rsm = (textures, backend.target(list(textures.values()), backend.depth_texture(size)))
        return self.rsm


def table(suns: list[Light], taps: np.ndarray, bounds: tuple[np.ndarray, np.ndarray],
          tile_texels: int) -> tuple[np.ndarray, list]:
    """The sky table (rows, TABLE_TEXELS, 4) float32 and each direction's LightView: a sun's RSM view
    (light_views._sun_view) at the tile's size, what its shadow draw (and its RSM tile) use. `taps`
    (len(suns), rays, 4): each region's rays and their shares (world.region_taps), texels 6 on."""
    rows = np.zeros((len(suns), TABLE_TEXELS + taps.shape[1], 4), np.float32)
    views = []
    # A tile's RSM (rsm_tiles) weighs its surfels' areas by its share of the sky's power: vct caps all the
    # tiles' VPLs as one light, against their lit cross-section, which a surface every direction lights
    # then counts once; a dominant sun's tile keeps the cap a lamp gets.
    shares = power_shares(suns)
    for k, sun in enumerate(suns):
        (view,) = views_for(sun, k, bounds, tile_texels)
        view.uniforms["area_weight"] = float(shares[k])
        rows[k, :4] = view.view_projection
        rows[k, 4] = (*view.face_axis, math.sqrt(view.texel_scale))
        rows[k, 5] = (*(sun.color * sun.sun_strength), math.tan(sun.sun_angle_rad / 2.0))
        rows[k, TABLE_TEXELS:] = taps[k]
        views.append(view)
    return rows, views


def shadow(backend: Backend, target, mesh, layout: SkyLayout, views: list) -> None:
    """Every direction's shadow map into its tile; texels no geometry covers keep w = 0 (lit)."""
    backend.clear(target, color=(0, 0, 0, 0), depth=1.0)
    if mesh is None:
        return
    program = backend.program(SHADOW_SPEC)
    for k, view in enumerate(views):
        backend.draw(program, target, mesh, uniforms={"light_view_projection": view.view_projection,
                                                      "emit_axis": view.face_axis},
                     depth_test=True, viewport=layout.viewport(k))


def rsm_tiles(backend: Backend, target, mesh, albedo_atlas, layout: SkyLayout, views: list) -> None:
    """Every direction's RSM (passes/rsm.py, a sun's view at the tile's size; `albedo_atlas` its
    textures) into its tile of the textures behind `target` (position, normal, flux): the world's VPLs,
    one tile per region of the sky, for a method that injects them all at once (vct)."""
    backend.clear(target, color=(0, 0, 0, 0), depth=1.0)
    for k, view in enumerate(views):
        rsm.draw(backend, target, mesh, view, albedo_atlas, viewport=layout.viewport(k))


def bounds(backend: Backend, atlas, out, layout: SkyLayout) -> None:
    """The atlas's depth bounds (SKY_BOUNDS) into `out` (layout.blocks)."""
    backend.dispatch(backend.program(BOUNDS_SPEC), group_count(layout.blocks, BOUNDS_SPEC.local_size),
                     uniforms={"tile_texels": layout.tile_texels}, samplers={"sky_depth_atlas": atlas},
                     images={"sky_bounds": out})


@dataclass
class BvhTextures:
    """bvh.py's hierarchy on the GPU (BVH): `nodes` (bvh.node_table), `triangles` (leaf order,
    rsm.occluder_table's layout) and the leaf count."""

    nodes: object
    triangles: object
    leaves: int

    @classmethod
    def upload(cls, backend: Backend, triangles_m: np.ndarray) -> BvhTextures:
        tree = bvh.build(triangles_m)
        nodes = bvh.node_table(tree)
        leaf_order = rsm.occluder_table(bvh.leaf_triangles(tree, triangles_m))
        return cls(backend.texture((nodes.shape[1], nodes.shape[0]), data=nodes),
                   backend.texture((leaf_order.shape[1], leaf_order.shape[0]), data=leaf_order), tree.leaves)


def direct(backend: Backend, gbuf_position, gbuf_normal, atlas, sky_bounds, sky_table, out, layout: SkyLayout,
           scene_diagonal_m: float, accumulate: bool = True, texel_list=None, rays: int = 0,
           tree: BvhTextures | None = None, exact_near_texels: float = direct_light.CAMERA_NEAR_TEXELS) -> None:
    """`scene_diagonal_m`: the bounds' diagonal, the farthest a blocker can be from its receiver (it
    sizes the blocker search: the widest penumbra). accumulate: add to `out`; False: replace its pixels
    that see geometry (those that see none are not written). texel_list: shade only the texels it
    lists (probe_capture.texel_list) instead of every pixel. rays: the rays per region the table holds,
    tested against `tree` (the triangles the shadow maps draw), skipping crossings nearer than
    `exact_near_texels` (direct_light.CAMERA_NEAR_TEXELS); 0: the shadow maps' filter."""
    spec = DIRECT_SPECS[texel_list is not None, rays > 0]
    samplers = {"gbuf_position": gbuf_position, "gbuf_normal": gbuf_normal, "sky_depth_atlas": atlas,
                "sky_bounds": sky_bounds, "sky_table": sky_table}
    uniforms = {"sky_count": layout.count, "tiles_x": layout.tiles_x, "tile_texels": layout.tile_texels,
                "scene_diagonal_m": scene_diagonal_m}
    if rays:
        samplers.update(bvh_nodes=tree.nodes, bvh_triangles=tree.triangles)
        uniforms.update(sky_rays=rays, bvh_leaves=tree.leaves, exact_near_texels=exact_near_texels)
    if texel_list is not None:
        samplers["texel_list"] = texel_list
    chunk = RAY_DIRECTIONS_PER_DISPATCH if rays else layout.count
    for first in range(0, layout.count, chunk):
        backend.dispatch(backend.program(spec), group_count((texel_list or out).size, spec.local_size),
                         uniforms={**uniforms, "sky_first": first, "sky_chunk": chunk,
                                   "accumulate": int(accumulate or first > 0)},
                         samplers=samplers, images={"direct": out})
