"""What differs between the Blender versions Bounce runs on (the manifest says 4.2 and newer), in one place.

Each function hides one difference found by running the same code in Blender 4.3.2 (Debian's binary,
Python 3.13) and the bpy module 5.0.1 (`make test-blender` runs the former, `make test` the latter);
docs/ARCHITECTURE.md lists them. Code elsewhere calls these instead of testing `bpy.app.version`.
"""

from __future__ import annotations

import bpy
import gpu

# Blender 5.0 always gives new materials and worlds a node tree and deprecates `use_nodes`.
_NODES_ALWAYS = bpy.app.version >= (5, 0, 0)


def node_tree(idblock):
    """The node tree of a new material or world, made on 4.x (where `*.new()` makes none until
    `use_nodes` is set) and left as it is on 5.x."""
    if idblock.node_tree is None:
        idblock.use_nodes = True
    return idblock.node_tree


def uses_nodes(idblock) -> bool:
    """Whether Cycles shades a material or world with its node tree (else its plain colour): on 4.x a
    tree may exist with `use_nodes` off; on 5.x there is no such switch (reading it warns)."""
    if idblock.node_tree is None:
        return False
    return _NODES_ALWAYS or bool(idblock.use_nodes)


def light_exposure_factor(light_data) -> float:
    """2^exposure: the factor Blender 4.4+ applies to a lamp's power or strength (Light > Exposure, in
    stops); 1 on versions without the setting."""
    return 2.0 ** float(getattr(light_data, "exposure", 0.0))


def clear_light_exposure(light_data) -> None:
    """Exposure 0 where the setting exists, so a lamp's power is its energy alone."""
    if hasattr(light_data, "exposure"):
        light_data.exposure = 0.0


def normalize_area_power(light_data) -> None:
    """An area light's energy as its total power whatever its size: Blender 5.0's Normalize on; 4.x
    has no such switch and always normalizes."""
    if hasattr(light_data, "normalize"):
        light_data.normalize = True


def area_power_normalized(light_data) -> bool:
    """Whether an area light's energy is its total power (Normalize on, or a version without it)."""
    return bool(getattr(light_data, "normalize", True))


# How GPUFrameBuffer takes {"texture": t, "layer": k}. Blender 4.3 built against Python 3.13 matches
# the attachment dict's keys inverted (a key is taken as "texture" when it is *not* "texture", and so
# on): the documented dict raises "'GPUTexture' object cannot be interpreted as an integer", while
# {"layer": t, "texture": k} attaches texture t's layer k. The documented form is tried first; it
# raises on a build with the inversion, and the swapped form raises on every build without it, so
# the probe cannot pick the wrong one. The real-Blender tier's lpv and vct overlays (which splat into
# 3D-texture layers) draw on 4.3; tests/blender checks those passes equal moderngl's on 5.0.
_layer_keys: tuple[str, str] | None = None


def multilayer_exr(image_settings) -> None:
    """Render output as 32-bit multi-layer OpenEXR. Blender 5.0 files the formats under a media type that
    must be set before the file format (FACTS.md); 4.x has no media type."""
    if hasattr(image_settings, "media_type"):
        image_settings.media_type = "MULTI_LAYER_IMAGE"
    image_settings.file_format = "OPEN_EXR_MULTILAYER"
    image_settings.color_depth = "32"


def layer_attachment(texture: gpu.types.GPUTexture, layer: int) -> dict:
    """A color slot for GPUFrameBuffer(color_slots=...) that attaches one layer of a 3D texture."""
    keys = _layer_keys or ("texture", "layer")
    return {keys[0]: texture, keys[1]: int(layer)}


def framebuffer(color_slots: tuple, depth_slot=None) -> gpu.types.GPUFrameBuffer:
    """GPUFrameBuffer whose layer slots (from `layer_attachment`) work on this build."""
    global _layer_keys
    try:
        return gpu.types.GPUFrameBuffer(color_slots=color_slots, depth_slot=depth_slot)
    except (TypeError, ValueError):
        if _layer_keys is not None or not any(isinstance(s, dict) for s in color_slots):
            raise
    _layer_keys = ("layer", "texture")
    swapped = tuple({"layer": s["texture"], "texture": s["layer"]} if isinstance(s, dict) else s for s in color_slots)
    return gpu.types.GPUFrameBuffer(color_slots=swapped, depth_slot=depth_slot)
