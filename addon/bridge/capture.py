"""Blender depsgraph -> engine Scene (numpy, world space, metres, Cycles' light units).

What is captured, and why:
- Geometry comes from the *evaluated* depsgraph (`depsgraph.object_instances`), so modifiers,
  collection instances and geometry-nodes instances appear as Cycles renders them. Objects hidden from
  render (`hide_render`, or every collection holding them hidden from render) and holdout objects are
  left out; objects with `visible_camera` off are kept (Cycles still bounces light off them) and marked
  in `Scene.camera_visible`.
- Triangles from `mesh.loop_triangles`; corner normals (`mesh.corner_normals`, which includes custom and
  split normals) go to world space by the inverse transpose. Triangles with NaN/Inf corners or zero area
  (after the transform) are dropped and counted in one warning.
- Albedo is what Cycles' *Diffuse Color* pass shows: base colour x (1 - metallic) x (1 - transmission)
  x the dielectric specular layer's attenuation (see `specular_layer_factor`). The bounce albedo
  (`Scene.bounce_albedo`, what the emitters of indirect light reflect with) leaves that layer out, as
  Cycles does after a diffuse bounce. Emission is radiance
  W/m^2/sr (colour x strength). Node setups we cannot read give albedo 0.8 and a warning, never silence.
- Lengths are multiplied by `scene.unit_settings.scale_length` (Blender units -> metres). Light power
  (W) and sun strength (W/m^2) are taken as they are: Cycles does not rescale them with the unit scale.
- `SceneCache` keeps object-space triangles per instance, so an update that moves a light re-reads no
  mesh and one that moves an object only re-applies its matrix.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import NamedTuple

import bpy
import numpy as np

from ..engine.scene import AREA_SHAPES, AlbedoTextures, Camera, Light, Scene
from ..engine.world import directions as world_directions
from . import compat, world_capture

NEUTRAL_ALBEDO = 0.8  # Cycles' own fallback surface is a 0.8 grey diffuse

# Dielectric layer attenuation of the diffuse lobe at normal incidence, measured on Cycles 5.0.1 (Diffuse
# Color pass of a plane seen head-on, 1 spp): factor = 1 - F0 * K(roughness), F0 = ((ior-1)/(ior+1))^2
# x 2 x Specular IOR Level. K is within 1 % for IOR 1.33-1.5 and levels 0.25-1 below roughness 0.6,
# within 4-10 % at roughness 0.8-1 for high F0. Index = roughness 0, 0.1, ..., 1.
_K_ROUGHNESS = np.array([1.0, 1.0, 0.9989, 0.9938, 0.9766, 0.9346, 0.8551, 0.7380, 0.5997, 0.4628, 0.3447])


def specular_layer_factor(level: float, ior: float = 1.5, roughness: float = 0.5) -> float:
    """How much Principled BSDF's dielectric layer scales the diffuse albedo (Cycles' Diffuse Color pass).

    Exact 1 at level 0 (no layer). Measured at normal incidence: 0.9626 at the defaults (level 0.5,
    IOR 1.5, roughness 0.5), 0.9254 at level 1. Cycles evaluates it per view direction: at 60 degrees
    from the normal the default gives 0.932, at 75 degrees 0.878, at 85 degrees 0.813 (rougher: flatter,
    smoother: steeper). A per-triangle albedo cannot hold that, so we keep the head-on value.
    """
    f0 = ((ior - 1.0) / (ior + 1.0)) ** 2 * 2.0 * max(level, 0.0)
    k = float(np.interp(min(max(roughness, 0.0), 1.0), np.linspace(0.0, 1.0, 11), _K_ROUGHNESS))
    return float(1.0 - min(f0, 1.0) * k)


def _np(matrix) -> np.ndarray:
    """mathutils.Matrix -> numpy row-major float64 (mathutils indexes [row][col] too)."""
    return np.array([list(row) for row in matrix], dtype=np.float64)


def _scale_matrix(s: float) -> np.ndarray:
    return np.diag([s, s, s, 1.0])


def image_size(scene, long_side: int) -> tuple[int, int]:
    """(w, h) with the render's aspect ratio and the longer side `long_side` pixels."""
    rx, ry = scene.render.resolution_x, scene.render.resolution_y
    if rx >= ry:
        return int(long_side), max(1, round(long_side * ry / rx))
    return max(1, round(long_side * rx / ry)), int(long_side)


def camera_for(scene_obj_camera, depsgraph, width: int, height: int) -> Camera:
    """The camera object's view and OpenGL-style projection for a width x height image, in metres.

    Lengths are scaled by the unit scale s, so view_m = S V S^-1 (rigid, translation in metres) and
    projection_m = P S^-1 (clip planes in metres): view_projection of a point in metres equals Blender's
    of the same point in Blender units.
    """
    cam = scene_obj_camera.evaluated_get(depsgraph)
    r = depsgraph.scene.render
    proj = _np(cam.calc_matrix_camera(depsgraph, x=int(width), y=int(height),
                                      scale_x=r.pixel_aspect_x, scale_y=r.pixel_aspect_y))
    view = _np(cam.matrix_world.inverted())
    s = depsgraph.scene.unit_settings.scale_length or 1.0
    S, S_inv = _scale_matrix(s), _scale_matrix(1.0 / s)
    return Camera(view=S @ view @ S_inv, projection=proj @ S_inv, width=int(width), height=int(height))


# --------------------------------------------------------------------------------------------- materials

def _srgb_to_linear(c: np.ndarray) -> np.ndarray:
    return np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)


# What Cycles reads from an image it cannot load (a missing or unreadable file): magenta, its kernel's
# IMAGE_TEXTURE_MISSING_RGBA. The capture reads the same, so Bounce lights the scene Cycles renders.
MISSING_IMAGE_RGB = (1.0, 0.0, 1.0)


def image_unreadable(image) -> bool:
    """Whether Blender could not load the image (its size is then 0 x 0)."""
    w, h = image.size
    return w * h == 0


def _image_texels(image) -> np.ndarray:
    """Linear RGB texels (h, w, 3) float32 (as the G-buffer samples them), row 0 = the image's bottom
    (Blender's order, v = 0); one magenta texel for an image Blender cannot load (MISSING_IMAGE_RGB). A
    loaded image has 4 channels, grey files too (checked on bpy 5.0 with one-channel EXR and PNG files)."""
    if image_unreadable(image):
        return np.array([[MISSING_IMAGE_RGB]], np.float32)
    w, h = image.size
    px = np.empty(w * h * image.channels, np.float32)
    image.pixels.foreach_get(px)
    rgb = px.reshape(h, w, image.channels)[..., :3].astype(np.float64)
    # Image.pixels of a byte image holds the file's encoded values; float buffers are already linear.
    if not image.is_float and image.colorspace_settings.name.lower().startswith("srgb"):
        rgb = _srgb_to_linear(rgb)
    return rgb.astype(np.float32)


# Dunavant's 6-point rule on the triangle (exact for polynomials of degree 4). Every point is inside,
# so a UV corner exactly on the texture's edge (u = 1) never wraps to the opposite side.
_A, _B = 0.816847572980459, 0.091576213509771
_C, _D = 0.108103018168070, 0.445948490915965
_TRI_POINTS = np.array([[_A, _B, _B], [_B, _A, _B], [_B, _B, _A], [_C, _D, _D], [_D, _C, _D], [_D, _D, _C]])
_TRI_WEIGHTS = np.array([0.109951743655322] * 3 + [0.223381589678011] * 3)


def triangle_texture_average(texels: np.ndarray, uv: np.ndarray) -> np.ndarray:
    """Mean colour (n, 3) of a texture over each triangle's UVs (n, 3, 2); repeat wrap, nearest texel."""
    h, w, _ = texels.shape
    pts = np.einsum("kc,ncd->nkd", _TRI_POINTS, uv)  # (n, 6, 2)
    x = np.floor(pts[..., 0] * w).astype(np.int64) % w
    y = np.floor(pts[..., 1] * h).astype(np.int64) % h
    return np.einsum("nkc,k->nc", texels[y, x], _TRI_WEIGHTS)


class UVTexture(NamedTuple):
    """An Image Texture read through the object's UV map: its image's name and texels (_image_texels),
    and how Cycles samples it (Closest interpolation; Extend rather than Repeat)."""

    name: str
    texels: np.ndarray
    nearest: bool
    clamp: bool


def _input_color(node, name: str, problems: list[str], images: dict, textures: list | None = None) -> np.ndarray:
    """A colour input's value: its constant, an RGB node, or an Image Texture's average colour.

    `textures`, when given, receives a UVTexture for an Image Texture read through the object's UV map
    (its Vector input unlinked): the caller then averages it per triangle (and the camera samples it
    per pixel) and uses the returned mean only where a mesh has no UVs."""
    sock = node.inputs[name]
    if not sock.is_linked:
        return np.array(sock.default_value[:3], np.float64)
    src = sock.links[0].from_node
    if src.type == "RGB":
        return np.array(src.outputs[0].default_value[:3], np.float64)
    if src.type in ("TEX_IMAGE", "TEX_ENVIRONMENT") and src.image is not None:
        key = src.image.name
        if key not in images:
            images[key] = _image_texels(src.image)
        if image_unreadable(src.image):
            problems.append(f"{name} <- image {key!r} ({src.image.filepath or 'no file'}) could not be "
                            f"loaded: magenta, as Cycles renders it")
        if textures is not None and src.type == "TEX_IMAGE" and not src.inputs["Vector"].is_linked:
            textures.append(UVTexture(key, images[key], src.interpolation == "Closest", src.extension == "EXTEND"))
        return images[key].reshape(-1, 3).mean(axis=0, dtype=np.float64)
    problems.append(f"{name} <- {src.bl_idname} (constant used)")
    return np.array(sock.default_value[:3], np.float64)


def _input_float(node, name: str, problems: list[str]) -> float:
    sock = node.inputs[name]
    if sock.is_linked:
        problems.append(f"{name} is linked (constant used)")
    return float(sock.default_value)


def _surface_node(tree, output_type: str, input_name: str):
    """The node feeding the active output's `input_name`, or None."""
    outs = [n for n in tree.nodes if n.type == output_type]
    active = [n for n in outs if getattr(n, "is_active_output", False)] or outs
    cycles = [n for n in active if getattr(n, "target", "ALL") in ("ALL", "CYCLES")] or active
    if not cycles or not cycles[0].inputs[input_name].is_linked:
        return None
    return cycles[0].inputs[input_name].links[0].from_node


def _closures(node, weight: float, problems: list[str]) -> list[tuple[float, object]]:
    """The shader nodes whose closures a surface sums, each with its weight: through Add Shader (both
    inputs, 1 each), Mix Shader (1 - Fac and Fac) and reroutes, as Cycles adds closures. An unlinked
    shader input adds nothing, as in Cycles."""
    if node.type == "REROUTE":
        links = node.inputs[0].links
        return _closures(links[0].from_node, weight, problems) if links else []
    if node.type == "ADD_SHADER":
        parts = ((node.inputs[0], 1.0), (node.inputs[1], 1.0))
    elif node.type == "MIX_SHADER":
        fac_socket = node.inputs[0]  # "Fac" in Blender 4, "Factor" in 5
        if fac_socket.is_linked:
            problems.append("Mix Shader factor is linked (constant used)")
        fac = min(max(float(fac_socket.default_value), 0.0), 1.0)
        parts = ((node.inputs[1], 1.0 - fac), (node.inputs[2], fac))
    else:
        return [(weight, node)]
    out: list[tuple[float, object]] = []
    for sock, share in parts:
        if sock.is_linked and share > 0:
            out += _closures(sock.links[0].from_node, weight * share, problems)
    return out


# Closures that reflect no diffuse light and emit none: with reflective caustics off Cycles drops them
# after a diffuse bounce, and its Diffuse Color pass leaves them out. Their glossy lobe is
# material_glossy's.
_GLOSSY_ONLY = ("BSDF_GLOSSY",)


def material_values(mat, images: dict | None = None, textures: list | None = None
                    ) -> tuple[np.ndarray, np.ndarray, str | None, np.ndarray]:
    """(albedo, emission, warning or None, bounce albedo) of a material: albedo as Cycles' Diffuse Color
    pass sees it, and as another diffuse surface sees it (Scene.bounce_albedo: without the specular
    layer, which Cycles drops after a diffuse bounce). A surface of several closures (Add and Mix
    Shader) sums them, each times its weight.

    With `textures` (a list), a Base Color image texture read through UVs is appended to it (a
    UVTexture) and the returned albedo is the texture's average times the rest of the factors:
    per-triangle albedo is then albedo / average x the texture's mean over the triangle, and the
    camera's albedo at a pixel albedo / average x the texel there (`_material_arrays`). Only a surface
    of one closure gives its texture; several take their averages."""
    images = {} if images is None else images
    if mat is None:
        grey = np.full(3, NEUTRAL_ALBEDO)  # Cycles' default surface
        return grey, np.zeros(3), None, grey
    if not compat.uses_nodes(mat):
        colour = np.array(mat.diffuse_color[:3], np.float64)
        return colour, np.zeros(3), None, colour
    node = _surface_node(mat.node_tree, "OUTPUT_MATERIAL", "Surface")
    problems: list[str] = []
    parts = _closures(node, 1.0, problems) if node is not None else []
    unsupported = [n.bl_idname for _, n in parts
                   if n.type not in ("BSDF_PRINCIPLED", "EMISSION", "BSDF_DIFFUSE", *_GLOSSY_ONLY)]
    if node is None or unsupported:
        kind = "no surface" if node is None else ", ".join(unsupported)
        grey = np.full(3, NEUTRAL_ALBEDO)
        return grey, np.zeros(3), (
            f"material {mat.name!r}: unsupported surface ({kind}); albedo {NEUTRAL_ALBEDO} used"), grey
    single_textures = textures if len(parts) == 1 else None
    albedo, bounce, emission = np.zeros(3), np.zeros(3), np.zeros(3)
    for weight, part in parts:
        part_albedo, part_bounce, part_emission = _closure_values(part, problems, images, single_textures)
        albedo += weight * part_albedo
        bounce += weight * part_bounce
        emission += weight * part_emission
    warn = f"material {mat.name!r}: " + "; ".join(problems) if problems else None
    return np.clip(albedo, 0.0, 1.0), np.maximum(emission, 0.0), warn, np.clip(bounce, 0.0, 1.0)


def _closure_values(node, problems: list[str], images: dict, textures: list | None
                    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(albedo, bounce albedo, emission) of one shader node of a kind material_values supports."""
    if node.type == "BSDF_PRINCIPLED":
        base = _input_color(node, "Base Color", problems, images, textures)
        metallic = _input_float(node, "Metallic", problems)
        transmission = _input_float(node, "Transmission Weight", problems)
        level = _input_float(node, "Specular IOR Level", problems)
        ior = _input_float(node, "IOR", problems)
        rough = _input_float(node, "Roughness", problems)
        bounce = np.clip(base * (1 - metallic) * (1 - transmission), 0.0, 1.0)
        for layer in ("Coat Weight", "Sheen Weight", "Subsurface Weight"):
            if _input_float(node, layer, problems) > 0:
                problems.append(f"{layer} > 0 ignored")
        emission = _input_color(node, "Emission Color", problems, images) * _input_float(
            node, "Emission Strength", problems)
        return bounce * specular_layer_factor(level, ior, rough), bounce, emission
    if node.type == "EMISSION":
        emission = _input_color(node, "Color", problems, images) * _input_float(node, "Strength", problems)
        return np.zeros(3), np.zeros(3), emission
    if node.type == "BSDF_DIFFUSE":
        colour = np.clip(_input_color(node, "Color", problems, images, textures), 0.0, 1.0)
        return colour, colour, np.zeros(3)
    return np.zeros(3), np.zeros(3), np.zeros(3)  # _GLOSSY_ONLY


def material_glossy(mat, images: dict | None = None) -> tuple[np.ndarray, float]:
    """(F0, roughness) of a material's GGX lobe (Scene.specular / roughness); (0, 1) where it has none.

    Principled BSDF: metals reflect their base colour; the dielectric layer ((ior - 1) / (ior + 1))^2 x
    2 x Specular IOR Level (0.5: the IOR's own F0) x Specular Tint, over what is not metal. Glossy
    BSDF: its colour at every angle (no Fresnel). Several closures (Add and Mix Shader): their F0s
    summed with their weights, the roughness of the one that reflects most. Other surfaces (Diffuse,
    Emission, unsupported) carry no glossy lobe here."""
    images = {} if images is None else images
    tree = mat.node_tree if mat is not None and compat.uses_nodes(mat) else None
    node = _surface_node(tree, "OUTPUT_MATERIAL", "Surface") if tree is not None else None
    problems: list[str] = []  # material_values reports the same inputs' problems once
    f0, rough, strongest = np.zeros(3), 1.0, 0.0
    for weight, part in _closures(node, 1.0, problems) if node is not None else []:
        if part.type == "BSDF_PRINCIPLED":
            base = _input_color(part, "Base Color", problems, images)
            metallic = min(max(_input_float(part, "Metallic", problems), 0.0), 1.0)
            ior = max(_input_float(part, "IOR", problems), 1.0)
            level = max(_input_float(part, "Specular IOR Level", problems), 0.0)
            tint = _input_color(part, "Specular Tint", problems, images)
            dielectric = min(((ior - 1.0) / (ior + 1.0)) ** 2 * 2.0 * level, 1.0) * tint
            part_f0 = metallic * base + (1.0 - metallic) * dielectric
        elif part.type in _GLOSSY_ONLY:
            part_f0 = _input_color(part, "Color", problems, images)
        else:
            continue
        part_f0 = weight * np.clip(part_f0, 0.0, 1.0)
        f0 = f0 + part_f0
        if part_f0.mean() > strongest:
            strongest = float(part_f0.mean())
            rough = min(max(_input_float(part, "Roughness", problems), 0.0), 1.0)
    return np.clip(f0, 0.0, 1.0), rough


def world_color(world, warnings: list[str]) -> np.ndarray:
    """Constant world radiance: Background colour x strength (textures -> their average + a warning)."""
    if world is None:
        return np.zeros(3)
    if not compat.uses_nodes(world):
        return np.array(world.color[:3], np.float64)
    node = _surface_node(world.node_tree, "OUTPUT_WORLD", "Surface")
    if node is None:
        return np.zeros(3)
    if node.type != "BACKGROUND":
        warnings.append(f"world {world.name!r}: unsupported surface ({node.bl_idname}); black used")
        return np.zeros(3)
    problems: list[str] = []
    color = _input_color(node, "Color", problems, {}) * _input_float(node, "Strength", problems)
    if node.inputs["Color"].is_linked:  # an average stands in for any texture: say so
        problems.append("textured background replaced by its average colour")
    if problems:
        warnings.append(f"world {world.name!r}: " + "; ".join(problems))
    return np.maximum(color, 0.0)


# ----------------------------------------------------------------------------------------------- geometry

@dataclass
class _Block:
    """One instance's triangles in object space, plus what is needed to put them in the world."""

    local_pos: np.ndarray      # (n, 3, 3) float64, Blender units, object space
    local_nrm: np.ndarray      # (n, 3, 3) float64, object space
    mat_index: np.ndarray      # (n,) int, material slot per triangle
    uv: np.ndarray | None      # (n, 3, 2) active render UV map, or None
    source: str                # name of the object whose geometry this is (for update tagging)
    instancer: str             # name of the instancing object ("" for a plain object)
    fingerprint: tuple = ()    # identity of the evaluated geometry (see _fingerprint)
    matrix: np.ndarray | None = None
    world: tuple | None = None  # cached (positions_m, normals, keep mask, dropped count)


def _read_local(obj) -> tuple | None:
    """Object-space triangles, corner normals, material indices and UVs (active render map, or None)
    of an evaluated object."""
    mesh, tmp = None, False
    if obj.type == "MESH":
        mesh = obj.data
    elif obj.type in ("CURVE", "FONT", "SURFACE", "META"):
        mesh, tmp = obj.to_mesh(), True
    if mesh is None:
        return None
    try:
        mesh.calc_loop_triangles()
        nt, nv, nl = len(mesh.loop_triangles), len(mesh.vertices), len(mesh.loops)
        co = np.empty(nv * 3, np.float64)
        mesh.vertices.foreach_get("co", co)
        tri_v = np.empty(nt * 3, np.int64)
        tri_l = np.empty(nt * 3, np.int64)
        mi = np.empty(nt, np.int64)
        mesh.loop_triangles.foreach_get("vertices", tri_v)
        mesh.loop_triangles.foreach_get("loops", tri_l)
        mesh.loop_triangles.foreach_get("material_index", mi)
        cn = np.empty(nl * 3, np.float64)
        mesh.corner_normals.foreach_get("vector", cn)  # 4.1+: custom/split normals included
        uv_layer = next((layer for layer in mesh.uv_layers if layer.active_render), None)
        uv = None
        if uv_layer is not None:
            uv_flat = np.empty(nl * 2, np.float64)
            uv_layer.uv.foreach_get("vector", uv_flat)
            uv = uv_flat.reshape(-1, 2)[tri_l].reshape(nt, 3, 2)
    finally:
        if tmp:
            obj.to_mesh_clear()
    pos = co.reshape(-1, 3)[tri_v].reshape(nt, 3, 3)
    nrm = cn.reshape(-1, 3)[tri_l].reshape(nt, 3, 3)
    return pos, nrm, mi, uv


def _fingerprint(obj) -> tuple:
    """Identity of an evaluated object's geometry. Re-evaluating geometry (a modifier or mesh change
    under modifiers) gives a new evaluated mesh with a new session_uid/pointer; a transform does not.
    A safety net for calls outside depsgraph_update_post, where depsgraph.updates is empty."""
    data = obj.data
    if data is None:
        return ()
    counts = (len(data.vertices), len(data.polygons)) if obj.type == "MESH" else ()
    return (data.session_uid, data.as_pointer(), *counts)


def _to_world(block: _Block, scale: float) -> tuple:
    """World positions (metres) and normals of a block; drops NaN/Inf and zero-area triangles."""
    m = block.matrix
    pos = (block.local_pos @ m[:3, :3].T + m[:3, 3]) * scale
    nrm = block.local_nrm @ np.linalg.inv(m[:3, :3])  # row vectors: n^T M^-1 = (M^-T n)^T
    nrm /= np.maximum(np.linalg.norm(nrm, axis=-1, keepdims=True), 1e-30)
    if np.linalg.det(m[:3, :3]) < 0:  # a mirror flips winding: keep it consistent with the normals
        pos, nrm = pos[:, [0, 2, 1]], nrm[:, [0, 2, 1]]
    area2 = np.linalg.norm(np.cross(pos[:, 1] - pos[:, 0], pos[:, 2] - pos[:, 0]), axis=-1)
    keep = np.isfinite(pos).all(axis=(1, 2)) & np.isfinite(nrm).all(axis=(1, 2)) & (area2 > 0)
    keep &= np.isfinite(area2)
    return pos[keep].astype(np.float32), nrm[keep].astype(np.float32), keep, int((~keep).sum())


def _render_hidden(obj) -> bool:
    """Left out of a final render: hide_render, holdout, or all its collections hidden from render."""
    o = obj.original
    if o.hide_render or getattr(o, "is_holdout", False):
        return True
    cols = o.users_collection
    return bool(cols) and all(c.hide_render for c in cols)


LIGHT_SWITCH = "bounce_include"


def define_light_switch() -> None:
    """Define the per-light switch on bpy.types.Light if the add-on has not (the CLI runs without it).
    Blender 5 keeps bpy.props values apart from custom properties: a saved value is only readable
    through a property defined under the same name, so the CLI defines the same one."""
    if not hasattr(bpy.types.Light, LIGHT_SWITCH):
        setattr(bpy.types.Light, LIGHT_SWITCH, bpy.props.BoolProperty(
            name="Bounce", description="Include this light in Bounce's direct and indirect light", default=True))


def light_included(light_data) -> bool:
    """The per-light switch (Light properties > Bounce); lamps are included by default."""
    return bool(getattr(light_data, LIGHT_SWITCH, True))


def _light(obj, m: np.ndarray, scale: float, warnings: list[str]) -> Light | None:
    """A Light from an evaluated lamp object and its world matrix (Blender units)."""
    ld = obj.data
    kind = ld.type
    if not light_included(obj.original.data):  # a UI switch: read it where the UI wrote it
        return None  # the user excluded it from Bounce (Light > Bounce: Include)
    if kind not in ("POINT", "SPOT", "SUN", "AREA"):
        warnings.append(f"light {obj.name!r}: type {kind} not supported, left out")
        return None
    axis_len = np.linalg.norm(m[:3, :3], axis=0)  # world length of local X, Y, Z
    kw = dict(kind=kind, position_m=m[:3, 3] * scale, direction=-m[:3, 2], color=np.array(ld.color[:3]),
              axis_x=m[:3, 0] / max(axis_len[0], 1e-30), name=obj.name)
    energy = float(ld.energy) * compat.light_exposure_factor(ld)  # what Cycles emits
    if kind == "SUN":
        kw.update(sun_strength=energy, sun_angle_rad=float(ld.angle))
    else:
        kw["power_w"] = energy
    if kind == "SPOT":
        kw.update(spot_size_rad=float(ld.spot_size), spot_blend=float(ld.spot_blend))
    if kind in ("POINT", "SPOT") and ld.shadow_soft_size > 0:
        warnings.append(f"light {obj.name!r}: radius {ld.shadow_soft_size:g} treated as a point light")
    if kind == "AREA":
        # Spread narrows the emission cone and an unnormalized power grows with the area: neither is
        # modelled (the emitter is Lambertian of total power `energy`), so the capture says so.
        if float(getattr(ld, "spread", np.pi)) < np.pi - 1e-4:
            warnings.append(f"light {obj.name!r}: spread {np.degrees(ld.spread):.0f} deg treated as 180 deg")
        if not compat.area_power_normalized(ld):
            warnings.append(f"light {obj.name!r}: Normalize is off; its power is taken as normalized")
        shape = ld.shape if ld.shape in AREA_SHAPES else "SQUARE"
        sy = ld.size_y if shape in ("RECTANGLE", "ELLIPSE") else ld.size
        # Cycles sizes an area light by its object scale too.
        kw.update(area_shape=shape, size_x_m=float(ld.size * axis_len[0] * scale),
                  size_y_m=float(sy * axis_len[1] * scale))
    return Light(**kw)


class SceneCache:
    """Incremental capture: object-space triangles per instance survive between updates.

    `update(depsgraph)` re-triangulates only instances that are new, whose object (or instancer) a
    depsgraph update tagged with is_updated_geometry, or whose evaluated mesh is a new one (fingerprint);
    a transform-only change re-applies the matrix to the cached object-space arrays. Call it from
    bpy.app.handlers.depsgraph_update_post: outside it depsgraph.updates is empty, and only the
    fingerprint sees changes (it misses in-place vertex edits of a mesh without modifiers).
    Lights, camera, world and materials are re-read every time (cheap;
    image averages are cached until an Image update). `geometry_reads` counts re-triangulated meshes.
    """

    def __init__(self, render_world: bool = True):
        """render_world: a world that varies with direction becomes a map, rendered by Cycles where
        Bounce cannot read it (world_capture.py, about 1.5 s per change); without, only a map that needs
        no render (an HDRI, or one already rendered for that node tree) and otherwise the world's average
        colour: the interactive viewport, where a Cycles render from a timer would stall the UI."""
        self.render_world = render_world
        self.blocks: dict[tuple, _Block] = {}
        self.images: dict[str, np.ndarray] = {}
        self.geometry_reads = 0
        self.scene: Scene | None = None
        self._dirty: set[str] = set()

    def note(self, depsgraph) -> None:
        """Remember what a depsgraph update tagged. `update` calls it itself; call it from every
        depsgraph_update_post whose update you skip (throttling), or edits made then are missed.
        depsgraph.updates is only filled inside that handler."""
        for u in depsgraph.updates:
            if isinstance(u.id, bpy.types.Object) and u.is_updated_geometry:
                self._dirty.add(u.id.original.name)
            elif isinstance(u.id, bpy.types.Image):
                self.images.pop(u.id.original.name, None)
                world_capture.forget()  # the world's map may read it

    def _capture_world(self, world, out: Scene) -> None:
        """The world's light into out.world_color (constant) or out.world_map (a map, with its mean as
        world_color): a world that varies with direction is rendered by Cycles unless render_world is
        off and no map is at hand (then its average colour, with a warning)."""
        captured = world_capture.capture(world, self.render_world) if world_capture.needs_map(world) else None
        if captured is not None:
            out.world_map = captured.map
            _, omega = world_directions(*captured.map.shape[:2])
            out.world_color = (np.tensordot(omega, captured.map, axes=2) / omega.sum()).astype(np.float32)
            out.lights = [*out.lights, *captured.suns]  # its suns (a sky's disc, an HDRI's sun): not in the map
            out.warnings.extend(world_capture.disc_warnings(world))
        else:
            out.world_color = world_color(world, out.warnings).astype(np.float32)

    def invalidate(self) -> None:
        """Forget everything: the next update re-reads every mesh."""
        self.blocks.clear()
        self.images.clear()

    def update(self, depsgraph, width: int | None = None, height: int | None = None) -> Scene:
        scene_bl = depsgraph.scene
        scale = scene_bl.unit_settings.scale_length or 1.0
        self.note(depsgraph)
        dirty, self._dirty = self._dirty, set()
        out = Scene()
        seen: dict[tuple, _Block] = {}
        lights: list[Light] = []
        mats: dict[str, tuple] = {}
        glossy: dict[str, tuple] = {}
        parts: list[tuple] = []
        uv_textures: dict[str, tuple[int, UVTexture]] = {}
        for inst in depsgraph.object_instances:
            obj = inst.object
            if inst.is_instance:
                # An instanced object's own hide_render counts; its collection's does not (instancing
                # collections are usually hidden or excluded themselves).
                if _render_hidden(inst.parent) or obj.original.hide_render:
                    continue
            elif not inst.show_self or _render_hidden(obj):
                continue
            m = _np(inst.matrix_world)
            if obj.type == "LIGHT":
                light = _light(obj, m, scale, out.warnings)
                if light is not None:
                    lights.append(light)
                continue
            if obj.type not in ("MESH", "CURVE", "FONT", "SURFACE", "META"):
                continue
            source = obj.original.name
            instancer = inst.parent.original.name if inst.is_instance else ""
            key = (source, instancer, tuple(inst.persistent_id) if inst.is_instance else ())
            block = self.blocks.get(key)
            fp = _fingerprint(obj)
            if block is None or source in dirty or instancer in dirty or block.fingerprint != fp:
                local = _read_local(obj)
                self.geometry_reads += 1
                if local is None:
                    continue
                block = _Block(*local, source=source, instancer=instancer, fingerprint=fp)
            if block.matrix is None or block.world is None or not np.array_equal(block.matrix, m):
                block.matrix, block.world = m, None
            if block.world is None:
                block.world = _to_world(block, scale)
            slots = [s.material for s in obj.material_slots]
            seen[key] = block
            # Hidden from the camera (Object > Visibility > Ray Visibility > Camera) but still bouncing
            # light, as in Cycles: the G-buffer leaves these triangles out, the RSMs keep them.
            seen_by_camera = obj.original.visible_camera and (
                not inst.is_instance or inst.parent.original.visible_camera)
            material = self._material_arrays(block, slots, mats, uv_textures)
            parts.append((*material[:5], *self._glossy_arrays(block, slots, glossy), seen_by_camera, *material[5:]))
        self.blocks = seen
        out.lights = lights
        dropped = sum(b.world[3] for b in seen.values())
        if dropped:
            out.warnings.append(f"{dropped} triangles with NaN/Inf corners or zero area dropped")
        for _, _, warn, _, _ in mats.values():
            if warn:
                out.warnings.append(warn)
        self._capture_world(scene_bl.world, out)
        if scene_bl.camera is not None:
            if width is None or height is None:
                pct = scene_bl.render.resolution_percentage / 100.0
                width = max(1, round(scene_bl.render.resolution_x * pct))
                height = max(1, round(scene_bl.render.resolution_y * pct))
            out.camera = camera_for(scene_bl.camera, depsgraph, width, height)
        if parts:
            out.positions_m = np.concatenate([p[0] for p in parts])
            out.normals = np.concatenate([p[1] for p in parts])
            out.albedo = np.concatenate([p[2] for p in parts]).astype(np.float32)
            out.emission = np.concatenate([p[3] for p in parts]).astype(np.float32)
            out.bounce_albedo = np.concatenate([p[4] for p in parts]).astype(np.float32)
            out.specular = np.concatenate([p[5] for p in parts]).astype(np.float32)
            out.roughness = np.concatenate([p[6] for p in parts]).astype(np.float32)
            out.camera_visible = np.concatenate([np.full(len(p[0]), p[7], bool) for p in parts])
            if uv_textures:
                ordered = [t for _, t in sorted(uv_textures.values(), key=lambda e: e[0])]
                out.albedo_textures = AlbedoTextures(
                    images=[t.texels for t in ordered], nearest=[t.nearest for t in ordered],
                    clamp=[t.clamp for t in ordered], index=np.concatenate([p[8] for p in parts]),
                    uv=np.concatenate([p[9] for p in parts]), scale=np.concatenate([p[10] for p in parts]),
                    bounce_scale=np.concatenate([p[11] for p in parts]))
        self.scene = out
        return out

    def _material_arrays(self, block: _Block, slots: list, mats: dict, uv_textures: dict) -> tuple:
        """A block's world triangles with per-triangle albedo/emission looked up from its material slots;
        an image-textured Base Color is averaged over each triangle's UVs. Also, for the albedo read
        per pixel (AlbedoTextures' fields): each triangle's texture (-1: none; an index into
        `uv_textures`, {image name: (index, UVTexture)}, which gains the block's new ones), corner UVs
        and the factors its texels are multiplied by (the camera's, the bounce's)."""
        pos, nrm, keep, _ = block.world
        table_a, table_e, table_b, table_tex = [], [], [], []
        for mat in slots or [None]:
            key = mat.name if mat is not None else None
            if key not in mats:
                textures: list = []
                mats[key] = (*material_values(mat, self.images, textures), textures[0] if textures else None)
            albedo_m, emission_m, _, bounce_m, texture_m = mats[key]
            table_a.append(albedo_m)
            table_e.append(emission_m)
            table_b.append(bounce_m)
            table_tex.append(texture_m)
        idx = np.clip(block.mat_index[keep], 0, len(table_a) - 1)  # Cycles clamps the index too
        albedo = np.asarray(table_a).reshape(-1, 3)[idx]
        bounce = np.asarray(table_b).reshape(-1, 3)[idx]
        n = len(idx)
        tex_index, tex_uv = np.full(n, -1, np.int32), np.zeros((n, 3, 2), np.float32)
        tex_scale, bounce_scale = np.zeros((n, 3), np.float32), np.zeros((n, 3), np.float32)
        if block.uv is not None:
            uv = block.uv[keep]
            for slot, texture in enumerate(table_tex):
                on = idx == slot
                if texture is not None and np.any(on):
                    mean = texture.texels.reshape(-1, 3).mean(axis=0, dtype=np.float64)
                    average = triangle_texture_average(texture.texels, uv[on])
                    for out, table, scales in ((albedo, table_a, tex_scale), (bounce, table_b, bounce_scale)):
                        scale = np.divide(table[slot], mean, out=np.zeros(3), where=mean > 0)
                        out[on] = np.clip(average * scale, 0.0, 1.0)
                        scales[on] = scale
                    entry = uv_textures.setdefault(texture.name, (len(uv_textures), texture))
                    tex_index[on], tex_uv[on] = entry[0], uv[on]
        return (pos, nrm, albedo, np.asarray(table_e).reshape(-1, 3)[idx], bounce, tex_index, tex_uv, tex_scale,
                bounce_scale)

    def _glossy_arrays(self, block: _Block, slots: list, glossy: dict) -> tuple:
        """Per-triangle F0 (n, 3) and roughness (n,) from the block's material slots."""
        table = []
        for mat in slots or [None]:
            key = mat.name if mat is not None else None
            if key not in glossy:
                glossy[key] = material_glossy(mat, self.images)
            table.append(glossy[key])
        idx = np.clip(block.mat_index[block.world[2]], 0, len(table) - 1)
        return np.asarray([t[0] for t in table]).reshape(-1, 3)[idx], np.asarray([t[1] for t in table])[idx]


def capture(depsgraph, width: int | None = None, height: int | None = None) -> Scene:
    """The whole scene of an evaluated depsgraph (see the module docstring); width/height: image size
    for the camera (default: render resolution x percentage). No camera -> Scene.camera is None."""
    return SceneCache().update(depsgraph, width, height)


__all__ = ["capture", "camera_for", "image_size", "SceneCache", "material_values", "material_glossy",
           "specular_layer_factor", "world_color", "NEUTRAL_ALBEDO"]
