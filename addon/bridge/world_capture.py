"""The world's radiance as an equirectangular map (engine/world.py's layout), for worlds that are not a
constant colour: an environment texture (HDRI), a Sky Texture, any node tree.

Bounce does not evaluate node trees itself: Cycles renders the world alone, from a panoramic
equirectangular camera at the origin, MAP_ROWS x MAP_COLS pixels, one sample per pixel (camera rays see
only the background: no noise but the filter, which is narrowed). That costs about 1.5 s on this
project's 2-core CPU machine (most of it Cycles' scene sync), so the map is cached by a fingerprint of
the world's node tree and rendered again only when that changes. A constant background (no link into
its Color) needs no render: capture.world_color gives it.

Cycles' equirectangular camera, rotated to look along +x with +z up, puts longitude increasing to the
left: its columns are read reversed to match world.py's layout (tests/blender/test_world_capture.py
renders a world whose colour is the view direction and checks every texel).
"""

from __future__ import annotations

import math
import os
import tempfile

import bpy
import numpy as np

from . import compat

MAP_ROWS, MAP_COLS = 32, 64
_cache: dict[str, np.ndarray] = {}


def needs_map(world) -> bool:
    """Whether the world's light varies with direction (its Background's Color is linked)."""
    if world is None or not compat.uses_nodes(world):
        return False
    out = next((n for n in world.node_tree.nodes if n.type == "OUTPUT_WORLD" and n.is_active_output), None)
    link = out.inputs["Surface"].links[0] if out is not None and out.inputs["Surface"].is_linked else None
    node = link.from_node if link is not None else None
    return node is not None and (node.type != "BACKGROUND" or node.inputs["Color"].is_linked)


def fingerprint(world) -> str:
    """Changes whenever anything in the world's node tree that can change its light changes: node
    types, input values, properties (a Sky Texture's sun is a node property), links, image names."""
    parts = [world.name]
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
            elif isinstance(value, bpy.types.ID):
                parts.append(f"{prop.identifier}=ID:{value.name}")
        for sock in node.inputs:
            if hasattr(sock, "default_value") and not sock.is_linked:
                v = sock.default_value
                parts.append(f"{sock.identifier}={tuple(v) if hasattr(v, '__len__') else v}")
    for link in tree.links:
        parts.append(f"{link.from_node.name}.{link.from_socket.identifier}>{link.to_node.name}.{link.to_socket.identifier}")
    return "|".join(parts)


def world_map(world) -> np.ndarray:
    """The world's radiance map (MAP_ROWS, MAP_COLS, 3) float32 W/m^2/sr, cached by fingerprint."""
    key = fingerprint(world)
    if key not in _cache:
        _cache.clear()  # one world at a time: a new fingerprint replaces the old map
        _cache[key] = _render(world)
    return _cache[key]


def _render(world) -> np.ndarray:
    scene = bpy.data.scenes.new("bounce_world_capture")
    cam_data = bpy.data.cameras.new("bounce_world_capture")
    cam = bpy.data.objects.new("bounce_world_capture", cam_data)
    path = os.path.join(tempfile.mkdtemp(prefix="bounce-world-"), "world.exr")
    image = None
    try:
        scene.collection.objects.link(cam)
        scene.camera, scene.world = cam, world
        cam_data.type = "PANO"
        cam_data.panorama_type = "EQUIRECTANGULAR"
        cam.rotation_euler = (math.pi / 2, 0.0, -math.pi / 2)  # looking along +x, +z up
        r = scene.render
        r.engine = "CYCLES"
        r.resolution_x, r.resolution_y, r.resolution_percentage = MAP_COLS, MAP_ROWS, 100
        scene.cycles.samples = 1
        scene.cycles.use_denoising = False
        scene.cycles.filter_width = 0.01  # each pixel its centre's direction, as world.py assumes
        scene.cycles.device = "CPU"
        r.image_settings.file_format = "OPEN_EXR"
        r.image_settings.color_depth = "32"
        bpy.ops.render.render(scene=scene.name)
        bpy.data.images["Render Result"].save_render(path, scene=scene)
        image = bpy.data.images.load(path)
        image.colorspace_settings.is_data = True  # the EXR holds linear radiance: read it as stored
        px = np.empty(MAP_ROWS * MAP_COLS * 4, np.float32)
        image.pixels.foreach_get(px)
    finally:
        if image is not None:
            bpy.data.images.remove(image)
        bpy.data.scenes.remove(scene)
        bpy.data.objects.remove(cam)
        bpy.data.cameras.remove(cam_data)
        if os.path.exists(path):
            os.remove(path)
            os.rmdir(os.path.dirname(path))
    rgb = px.reshape(MAP_ROWS, MAP_COLS, 4)[::-1, ::-1, :3]  # Blender rows bottom-up; columns mirrored
    return np.ascontiguousarray(np.maximum(rgb, 0.0), np.float32)
