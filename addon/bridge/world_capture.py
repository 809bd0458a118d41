"""The world's radiance as an equirectangular map (engine/world.py's layout), for worlds that are not a
constant colour: an environment texture (HDRI), a Sky Texture, any node tree.

The common case, an HDRI (an Environment Texture of a float image in a linear colour space, its
vector unlinked, straight into the Background's Color), is read directly: every image pixel is binned
into the map by its direction, weighted by its solid angle, so a small bright sun keeps its energy
(tens of milliseconds). Any other node tree (a Sky Texture, mixes, mappings) Bounce does not evaluate
itself: Cycles renders the world alone, from a panoramic equirectangular camera at the origin,
MAP_SUPERSAMPLE^2 pixels per texel of the MAP_ROWS x MAP_COLS map, one sample per pixel (camera rays
see only the background: no noise but the filter, which is narrowed), and each texel is the mean of
its pixels by solid angle (a texel's centre alone misses the horizon's steep band). That costs about
0.3 s on this project's 2-core CPU machine (most of it Cycles' scene sync), so the map is cached by a
fingerprint of the world's node tree and made again only when that changes. A constant background
(no link into its Color) needs no map: capture.world_color gives it.

The interactive viewport never renders from its timer (a stall of half a second per edit of the sky): it asks
`capture(world, render=False)`, which reads an HDRI (each image's binning cached apart from the
Background's strength, so dragging the strength re-reads nothing) and otherwise returns only a map
already made for this exact node tree: kept in the world by the Capture World Light operator (`store`:
saved with the .blend, keyed by the node tree and Blender's version), or rendered by a bake or a
render in the same session.

A Sky Texture's sun disc (on by default; half a degree wide) is about as wide as the render's
samples are apart (0.7 degrees): a sample hits it or misses it by chance, and most of a clear day's
light with it. So each disc Bounce can place (its Vector input unlinked) becomes a SUN light along the
node's sun direction, its irradiance measured by a second render, a pinhole view three disc diameters
wide around it (the pixels' excess over the sky at the view's border times their solid angles), and
the map is rendered from a copy of the world with those discs off, so nothing is counted twice
(`Captured.suns`). A disc turned by a linked Vector is not placed, with a warning (samples that hit it
by chance keep its light). An HDRI's sun is taken out of its pixels the same way (`_take_sun`) before
they are binned: a sun texel of the map would light through the sky pass's coarse shadow tiles from a
direction up to 1.4 degrees off.

Cycles' equirectangular camera, rotated to look along +x with +z up, puts longitude increasing to the
left: its columns are read reversed to match world.py's layout (tests/blender/test_world_capture.py
renders a world whose colour is the view direction and checks every texel).
"""

from __future__ import annotations

import hashlib
import math
import os
import tempfile
from typing import NamedTuple

import bpy
import numpy as np
from mathutils import Vector

from ..engine.scene import Light
from ..engine.world import LUMA, downsample
from . import compat

# 2.8 degrees a texel. The sky pass's directions are regions of whole texels (world.regions), and most
# of the light a window lets onto the far wall comes from a band a few texels high at the horizon: with
# 5.6-degree texels its brightest regions were single texels no direction count could split further,
# each casting the window's shadow as one disc (docs/DIRECT.md, "The map's resolution").
MAP_ROWS, MAP_COLS = 64, 128
# Pixels rendered per map texel and side. A sky's radiance changes fastest at the horizon: the ground's
# first 5.6 degrees of Blender's default Sky Texture average 2.4 times their centre's radiance. 4 x 4
# samples a texel: the same 256 x 512 render that held a 32-row map's texel means to ~1 % there.
MAP_SUPERSAMPLE = 4
_cache: dict[str, Captured] = {}
_binned_images: dict[tuple, tuple] = {}  # an HDRI's (map, suns) at strength 1, by (name, filepath, size)


def _background(world):
    out = next((n for n in world.node_tree.nodes if n.type == "OUTPUT_WORLD" and n.is_active_output), None)
    link = out.inputs["Surface"].links[0] if out is not None and out.inputs["Surface"].is_linked else None
    return link.from_node if link is not None else None


def _direct_hdri(world):
    """(image, strength) when the world is an HDRI this module reads itself (module docstring), else None."""
    bg = _background(world)
    if bg is None or bg.type != "BACKGROUND" or not bg.inputs["Color"].is_linked or bg.inputs["Strength"].is_linked:
        return None
    tex = bg.inputs["Color"].links[0].from_node
    image = getattr(tex, "image", None)
    if (tex.type != "TEX_ENVIRONMENT" or tex.projection != "EQUIRECTANGULAR" or tex.inputs["Vector"].is_linked
            or image is None or not image.is_float or image.colorspace_settings.name not in LINEAR_SPACES):
        return None
    return image, float(bg.inputs["Strength"].default_value)


LINEAR_SPACES = {"Linear Rec.709", "Linear", "Non-Color", "Linear CIE-XYZ E", "Linear Rec.2020"}


def _binned(world, image, strength: float) -> Captured:
    """The HDRI's map and sun at `strength` (read at strength 1 and cached per image: `_read_hdri`)."""
    key = (image.name, image.filepath, tuple(image.size))
    if key not in _binned_images:
        _binned_images[key] = _read_hdri(image)
    world_map, suns = _binned_images[key]
    return Captured((world_map * np.float32(strength)).astype(np.float32),
                    tuple(_sun_light(world, -toward, irradiance * strength, angle)
                          for toward, irradiance, angle in suns))


# An HDRI's sun: its pixels brighter than SUN_CONTRAST x the median luminance of its lit pixels within
# SUN_RADIUS_RAD of its brightest pixel (a photographed sun is 10^4-10^6 times the sky, blown out over
# a degree or two). Left in the 2.8-degree map it would light through a shadow map of the sky pass's
# tiles (64 texels across the scene: blurred shadows) from a texel centre up to 1.4 degrees off.
SUN_CONTRAST = 100.0
SUN_RADIUS_RAD = math.radians(5.0)


def _read_hdri(image) -> tuple[np.ndarray, list]:
    """The HDRI's pixels binned into the map by direction (Cycles' equirectangular mapping: u = 0.5 -
    atan2(y, x) / 2 pi, v = 0.5 + atan2(z, hypot(x, y)) / pi, row 0 = bottom), each weighted by its
    solid angle: the map texel's radiance is the mean over the image pixels it holds. Its sun (if any,
    SUN_CONTRAST) is taken out first: its pixels keep SUN_CONTRAST x the median, and what they had above
    that becomes one sun, (direction towards it, irradiance facing it per colour, angular diameter of a
    disc of its pixels' solid angle), so the map and the sun together hold the image's int L dw."""
    w, h = image.size
    px = np.empty(w * h * 4, np.float32)
    image.pixels.foreach_get(px)
    rgb = px.reshape(h, w, 4)[..., :3].astype(np.float64)
    v = (np.arange(h) + 0.5) / h                              # row 0 = bottom
    lat = (v - 0.5) * np.pi
    u = (np.arange(w) + 0.5) / w
    lon = (0.5 - u) * 2 * np.pi                                 # atan2(y, x) of each column
    weight = np.repeat(np.cos(lat)[:, None], w, axis=1)         # solid angle per pixel, up to a constant
    rgb, suns = _take_sun(rgb, lat, lon, weight * (np.pi / h) * (2 * np.pi / w))
    # world.py's layout: row 0 = up, column c at longitude 2 pi (c + 0.5) / MAP_COLS - pi
    rows = np.clip(((np.pi / 2 - lat) / np.pi * MAP_ROWS).astype(int), 0, MAP_ROWS - 1)
    cols = np.clip(((lon + np.pi) / (2 * np.pi) * MAP_COLS).astype(int) % MAP_COLS, 0, MAP_COLS - 1)
    index = (rows[:, None] * MAP_COLS + cols[None, :]).ravel()
    total = np.zeros((MAP_ROWS * MAP_COLS, 3))
    for c in range(3):
        total[:, c] = np.bincount(index, weights=(rgb[..., c] * weight).ravel(), minlength=MAP_ROWS * MAP_COLS)
    norm = np.bincount(index, weights=weight.ravel(), minlength=MAP_ROWS * MAP_COLS)
    out = total / np.maximum(norm, 1e-300)[:, None]
    return np.maximum(out, 0.0).reshape(MAP_ROWS, MAP_COLS, 3).astype(np.float32), suns


def _take_sun(rgb: np.ndarray, lat: np.ndarray, lon: np.ndarray, solid_angle: np.ndarray) -> tuple:
    """(rgb with its sun's excess removed, [the sun] or []) for an equirectangular image: rows at
    latitudes `lat`, columns at longitudes `lon`, pixels of `solid_angle` sr (module's SUN_CONTRAST)."""
    luma = np.maximum(rgb @ LUMA, 0.0)
    lit = luma[luma > 0.0]  # a sky dome's black lower half would put the median at 0
    if lit.size == 0:
        return rgb, []
    level = SUN_CONTRAST * float(np.median(lit))
    peak = np.unravel_index(np.argmax(luma), luma.shape)
    if luma[peak] <= level:
        return rgb, []
    cos_lat = np.cos(lat)[:, None]
    dirs = np.stack(np.broadcast_arrays(cos_lat * np.cos(lon)[None, :], cos_lat * np.sin(lon)[None, :],
                                        np.sin(lat)[:, None]), axis=-1)
    hot = (luma > level) & (dirs @ dirs[peak] > math.cos(SUN_RADIUS_RAD))
    keep = np.where(hot, level / np.maximum(luma, 1e-300), 1.0)[..., None]  # hot pixels down to `level`
    excess = rgb * (1.0 - keep)
    irradiance = np.einsum("ijc,ij->c", excess, solid_angle)
    toward = np.einsum("ij,ijk->k", (excess @ LUMA) * solid_angle, dirs)
    angle = 2.0 * math.sqrt(float(solid_angle[hot].sum()) / math.pi)
    return rgb * keep, [(toward / np.linalg.norm(toward), irradiance, angle)]


def needs_map(world) -> bool:
    """Whether the world's light varies with direction (its Background's Color is linked)."""
    if world is None or not compat.uses_nodes(world):
        return False
    node = _background(world)
    return node is not None and (node.type != "BACKGROUND" or node.inputs["Color"].is_linked)


def fingerprint(world, with_file: bool = True) -> str:
    """Changes whenever anything in the world's node tree that can change its light changes: node
    types, input values, properties (a Sky Texture's sun is a node property), links, image names; and,
    `with_file`, the .blend's path (the session's cache spans files, whose images may share names)."""
    parts = [bpy.data.filepath if with_file else "", world.name]
    tree = world.node_tree
    for node in sorted(tree.nodes, key=lambda n: n.name):
        parts.append(f"{node.name}:{node.bl_idname}")
        for prop in node.bl_rna.properties:
            if prop.identifier in {"rna_type", "location", "width", "height", "select", "name", "label"}:
                continue
            value = getattr(node, prop.identifier, None)
            if isinstance(value, (int, float, str, bool)):
                parts.append(f"{prop.identifier}={value}")
            elif hasattr(value, "__len__") and not isinstance(value, bpy.types.bpy_struct) and len(value) <= 16:
                parts.append(f"{prop.identifier}={tuple(value)}")
            elif isinstance(value, bpy.types.Image):  # a replaced or reloaded HDRI, not only a renamed one
                parts.append(f"{prop.identifier}=IM:{value.name}:{value.filepath}:{tuple(value.size)}")
            elif isinstance(value, bpy.types.ID):
                parts.append(f"{prop.identifier}=ID:{value.name}")
        for sock in node.inputs:
            if hasattr(sock, "default_value") and not sock.is_linked:
                v = sock.default_value
                parts.append(f"{sock.identifier}={tuple(v) if hasattr(v, '__len__') else v}")
    for link in tree.links:
        parts.append(f"{link.from_node.name}.{link.from_socket.identifier}>{link.to_node.name}.{link.to_socket.identifier}")
    return "|".join(parts)


def forget() -> None:
    """Drop the cached maps: an image was edited in place (capture.SceneCache.note calls this on an
    Image update, which the fingerprint cannot see)."""
    _cache.clear()
    _binned_images.clear()


class Captured(NamedTuple):
    """A world as Bounce lights with it: its radiance map (MAP_ROWS, MAP_COLS, 3) float32 W/m^2/sr, and
    its suns as SUN lights (Light), their light left out of the map: its Sky Textures' discs (half a
    degree, about the width of the render's pixels) or an HDRI's sun (`_take_sun`)."""

    map: np.ndarray
    suns: tuple = ()


def capture(world, render: bool = True) -> Captured | None:
    """The world's light, cached by fingerprint. With `render` False only what needs no Cycles render:
    an HDRI read directly, what the world stores for this node tree (`store`), or what was already made
    for it; None otherwise (the caller lights with the world's average)."""
    key = fingerprint(world)
    if key not in _cache:
        hdri = _direct_hdri(world)
        stored = stored_capture(world) if hdri is None else None
        if hdri is None and stored is None and not render:
            return None
        _cache.clear()  # one world at a time: a new fingerprint replaces the old map
        if hdri is not None:
            _cache[key] = _binned(world, *hdri)
        else:
            _cache[key] = stored if stored is not None else _render(world)
    return _cache[key]


def world_map(world, render: bool = True) -> np.ndarray | None:
    """capture's map alone (None where capture gives None)."""
    captured = capture(world, render)
    return None if captured is None else captured.map


# What the Capture World Light operator keeps in the world datablock (so in the .blend): the map, its
# suns (7 floats each: the direction the light travels, its irradiance per colour, its angular
# diameter) and the key of what they were rendered from: the node tree's fingerprint without the
# file's path (a saved copy keeps it) and Blender's version (another version may model the sky
# otherwise).
STORED_MAP, STORED_SUNS, STORED_KEY = "bounce_world_map", "bounce_world_suns", "bounce_world_key"


def _stored_key(world) -> str:
    # The map's size and sampling too: a map kept by a build that sampled the world otherwise is made again.
    text = f"{bpy.app.version_string}|{MAP_ROWS}x{MAP_COLS}x{MAP_SUPERSAMPLE}|{fingerprint(world, with_file=False)}"
    return hashlib.sha256(text.encode()).hexdigest()


def store(world, captured: Captured) -> None:
    """Keep `captured` in the world's custom properties (saved with the .blend, undone with undo)."""
    world[STORED_MAP] = np.asarray(captured.map, np.float64).ravel().tolist()
    world[STORED_SUNS] = [float(v) for sun in captured.suns
                          for v in (*sun.direction, *(sun.color * sun.sun_strength), sun.sun_angle_rad)]
    world[STORED_KEY] = _stored_key(world)


def stored_capture(world) -> Captured | None:
    """What `store` kept in the world, if it was made from the world as it is now; else None."""
    if world.get(STORED_KEY) != _stored_key(world) or STORED_MAP not in world:
        return None
    values = np.asarray(world[STORED_MAP], np.float32)
    suns = np.asarray(world.get(STORED_SUNS, []), np.float64)
    if values.size != MAP_ROWS * MAP_COLS * 3 or suns.size % 7:
        return None
    return Captured(np.maximum(values.reshape(MAP_ROWS, MAP_COLS, 3), 0.0),
                    tuple(_sun_light(world, row[:3], row[3:6], row[6]) for row in suns.reshape(-1, 7)))


def _sun_light(world, direction, irradiance, angle_rad: float) -> Light:
    """A SUN light travelling along `direction` with `irradiance` (W/m^2 per colour) facing it."""
    irradiance = np.maximum(np.asarray(irradiance, np.float64), 0.0)
    strength = float(irradiance.max())
    color = irradiance / strength if strength > 0 else np.ones(3)
    return Light("SUN", np.zeros(3), direction, color, sun_strength=strength, sun_angle_rad=float(angle_rad),
                 name=f"{world.name}: sun")


# Sky models that draw a sun disc (Blender 4.x names it NISHITA; 5.0 splits it in two).
DISC_SKIES = {"NISHITA", "SINGLE_SCATTERING", "MULTIPLE_SCATTERING"}


def sun_discs(world) -> list:
    """The world's Sky Texture nodes that draw a sun disc."""
    if world is None or world.node_tree is None:
        return []
    return [n for n in world.node_tree.nodes
            if n.type == "TEX_SKY" and n.sky_type in DISC_SKIES and getattr(n, "sun_disc", False)]


def disc_warnings(world) -> list[str]:
    """The sun discs Bounce cannot place: a Sky Texture whose Vector input is linked (a mapping turns
    its sky, so the node's own sun direction is not where the sun is)."""
    return [f"world {world.name!r}: the sun disc of {n.name!r} is turned by its linked Vector input and "
            "is left out (unlink it, or turn the disc off and add a Sun lamp)"
            for n in sun_discs(world) if _vector_linked(n)]


def _vector_linked(node) -> bool:
    """Whether the node's Vector input is in use and linked (5.0's scattering skies disable the socket,
    and a name lookup does not see a disabled socket)."""
    return any(s.identifier == "Vector" and getattr(s, "enabled", True) and s.is_linked for s in node.inputs)


def _render(world) -> Captured:
    """The map rendered by Cycles; each sun disc Bounce can place becomes a SUN light, measured by a
    render of a narrow view around it, and is left out of the map (rendered from a copy of the world
    with those discs off)."""
    discs = [n for n in sun_discs(world) if not _vector_linked(n)]
    if not discs:
        return Captured(_render_map(world))
    suns = tuple(sun for sun in (_measure_sun(world, node) for node in discs) if sun is not None)
    sky_only = world.copy()
    try:
        for node in discs:
            sky_only.node_tree.nodes[node.name].sun_disc = False
        return Captured(_render_map(sky_only), suns)
    finally:
        bpy.data.worlds.remove(sky_only)


def sun_direction(node) -> np.ndarray:
    """Unit vector towards a Sky Texture's sun: elevation above the horizon, rotation about +z from +y
    towards +x (checked against Cycles: the disc lies at the centre of a view along it)."""
    e, r = node.sun_elevation, node.sun_rotation
    return np.array([math.cos(e) * math.sin(r), math.cos(e) * math.cos(r), math.sin(e)])


SUN_VIEW_TEXELS = 64  # a side of the narrow view: the disc covers ~1/9 of it, ~350 point samples
# How much brighter than the brightest sky around it a pixel must be to be the disc: a sun's radiance
# is 10^4-10^5 times the sky's even at sunset (46 W/m^2 from 7e-5 sr against ~10 W/m^2/sr), a smooth
# sky's excess over its mean across 1.5 degrees a few per cent of it.
DISC_CONTRAST = 100.0


def _measure_sun(world, node) -> Light | None:
    """The sun disc of `node` as a SUN light: a pinhole view 3 disc diameters wide centred on the sun,
    each pixel's radiance above the sky around the disc (the mean of the view's border) times its solid
    angle, summed: the disc's irradiance facing it. None below the horizon (no disc in view)."""
    toward = sun_direction(node)
    half = 1.5 * node.sun_size
    n = SUN_VIEW_TEXELS

    def aim(cam_data, cam):
        cam_data.sensor_fit = "HORIZONTAL"
        cam_data.angle = 2.0 * half
        cam.rotation_euler = Vector(toward).to_track_quat("-Z", "Y").to_euler()

    radiance = _render_view(world, n, n, aim)
    border = np.concatenate([radiance[0], radiance[-1], radiance[1:-1, 0], radiance[1:-1, -1]])
    excess = np.maximum(radiance - border.mean(axis=0), 0.0)
    if excess.max() <= DISC_CONTRAST * max(float(border.max()), 1e-30):
        return None  # no disc in view, only the sky's own gradient across it
    t = math.tan(half)
    u = ((np.arange(n) + 0.5) / n * 2.0 - 1.0) * t
    x, y = np.meshgrid(u, u)
    solid_angle = (2.0 * t / n) ** 2 / (1.0 + x * x + y * y) ** 1.5  # a pinhole's pixels, image plane at 1
    return _sun_light(world, -toward, np.einsum("ijc,ij->c", excess, solid_angle), node.sun_size)


def _render_map(world) -> np.ndarray:
    """The world rendered from a panoramic equirectangular camera at the origin, MAP_SUPERSAMPLE^2
    pixels per texel of the MAP_ROWS x MAP_COLS map, averaged into it by solid angle."""

    def equirectangular(cam_data, cam):
        cam_data.type = "PANO"
        cam_data.panorama_type = "EQUIRECTANGULAR"
        cam.rotation_euler = (math.pi / 2, 0.0, -math.pi / 2)  # looking along +x, +z up

    k = MAP_SUPERSAMPLE
    rgb = _render_view(world, MAP_COLS * k, MAP_ROWS * k, equirectangular)
    fine = np.maximum(rgb[:, ::-1], 0.0)  # columns mirrored (module doc)
    return np.ascontiguousarray(downsample(fine, k), np.float32)


def _render_view(world, width: int, height: int, setup) -> np.ndarray:
    """The world alone rendered by Cycles from a camera at the origin that `setup(camera data, camera
    object)` points: (height, width, 3) float64 radiance, row 0 = top, one sample at each pixel centre."""
    scene = bpy.data.scenes.new("bounce_world_capture")
    cam_data = bpy.data.cameras.new("bounce_world_capture")
    cam = bpy.data.objects.new("bounce_world_capture", cam_data)
    path = os.path.join(tempfile.mkdtemp(prefix="bounce-world-"), "world.exr")
    image = None
    # Camera rays that meet nothing read the world's shader directly; the world's importance map, which
    # Cycles builds first for light sampling (a Sky Texture evaluated over a 1024-wide map), serves no ray
    # here and was two thirds of the capture's time. The same pixels come out without it.
    sampling = world.cycles.sampling_method
    world.cycles.sampling_method = "NONE"
    try:
        scene.collection.objects.link(cam)
        scene.camera, scene.world = cam, world
        setup(cam_data, cam)
        r = scene.render
        r.engine = "CYCLES"
        r.resolution_x, r.resolution_y, r.resolution_percentage = width, height, 100
        scene.cycles.samples = 1
        scene.cycles.use_denoising = False
        scene.cycles.filter_width = 0.01  # each pixel its centre's direction, as world.py assumes
        scene.cycles.device = "CPU"
        r.image_settings.file_format = "OPEN_EXR"
        r.image_settings.color_depth = "32"
        # The active Render Result slot shows the render of the scene it is looked at from: the user's
        # last render of their own scene stays what that slot shows (tests/blender/test_world_capture.py).
        bpy.ops.render.render(scene=scene.name)
        bpy.data.images["Render Result"].save_render(path, scene=scene)
        image = bpy.data.images.load(path)
        image.colorspace_settings.is_data = True  # the EXR holds linear radiance: read it as stored
        px = np.empty(width * height * 4, np.float32)
        image.pixels.foreach_get(px)
    finally:
        world.cycles.sampling_method = sampling
        if image is not None:
            bpy.data.images.remove(image)
        bpy.data.scenes.remove(scene)
        bpy.data.objects.remove(cam)
        bpy.data.cameras.remove(cam_data)
        if os.path.exists(path):
            os.remove(path)
            os.rmdir(os.path.dirname(path))
    return px.reshape(height, width, 4)[::-1, :, :3].astype(np.float64)  # Blender's rows are bottom-up
