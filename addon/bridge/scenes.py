"""Procedural benchmark scenes, built with bpy into a fresh empty file. Deterministic (no randomness),
metres, pure-Lambert materials (cornell-glossy adds glossy layers) and explicitly set light parameters,
so that every method can be compared with Cycles' diffuse passes on exactly the same input.

`SCENES` maps a name to its builder; `build(name)` makes the scene, `save(name, path)` writes it.
Each scene records its name in the custom property `scene["bounce_scene"]`.
"""

from __future__ import annotations

import math

import bpy
import numpy as np
from mathutils import Vector

from ..engine.errors import ConfigError, SceneError
from . import compat

# Cornell box albedos (linear), as in BASELINE.md.
RED = (0.63, 0.065, 0.05)
GREEN = (0.14, 0.45, 0.091)
WHITE = (0.725, 0.71, 0.68)

# Cornell spot light: BASELINE.md's light; the blend is part of the benchmark definition.
SPOT_POWER_W = 300.0
SPOT_SIZE_DEG = 70.0
SPOT_BLEND = 0.15

# thin-wall: a divider one cell thick of a 64^3 grid over 4 m (half a cell of 32^3): light leaking
# through it is the failure this scene exposes.
THIN_WALL = 0.0625
SHELL = 0.1  # thickness of the closed walls of window-room and thin-wall

# window-room: north wall (+y) opening, x in [-0.5, 0.5], z in [1, 2] (in-wall, 0.1 m deep).
WINDOW_X = (-0.5, 0.5)
WINDOW_Z = (1.0, 2.0)
WINDOW_SUN_DIR = (0.0, -1.0, -1.0)  # direction the sunlight travels: 45 degrees down, from the north


# --------------------------------------------------------------------------------------------- setup

def _reset(name: str, res: tuple[int, int]) -> bpy.types.Scene:
    """Empty file, exact resolution, metres, black world: nothing but what the builder adds emits."""
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    scene["bounce_scene"] = name
    scene.render.resolution_x, scene.render.resolution_y = res
    scene.render.resolution_percentage = 100
    scene.unit_settings.system = "METRIC"
    scene.unit_settings.scale_length = 1.0
    world = bpy.data.worlds.new("World")
    world.color = (0.0, 0.0, 0.0)
    background = compat.node_tree(world).nodes["Background"]
    background.inputs["Color"].default_value = (0.0, 0.0, 0.0, 1.0)
    background.inputs["Strength"].default_value = 0.0
    scene.world = world
    return scene


def _link(obj):
    bpy.context.scene.collection.objects.link(obj)
    return obj


def _look_at(obj, target) -> None:
    """Rotate obj so its -Z (the view/emission axis of cameras and lights) points at target."""
    direction = Vector(target) - obj.location
    obj.rotation_euler = direction.to_track_quat("-Z", "Y").to_euler()


def _camera(location, target, fov_deg: float):
    cam = bpy.data.cameras.new("Camera")
    cam.angle = math.radians(fov_deg)  # along the larger image side (sensor_fit AUTO)
    cam.clip_start, cam.clip_end = 0.01, 100.0
    obj = _link(bpy.data.objects.new("Camera", cam))
    obj.location = location
    _look_at(obj, target)
    bpy.context.scene.camera = obj
    return obj


def _light(name: str, kind: str, location, energy: float, direction=(0.0, 0.0, -1.0), **props):
    """A lamp with every parameter that changes its light set explicitly (bpy.data.lights.new defaults
    differ from lights made in the UI). Point and spot lights get radius 0: true point lights."""
    light = bpy.data.lights.new(name, kind)
    light.energy = energy  # W for point/spot/area, W/m^2 (strength) for sun
    light.color = (1.0, 1.0, 1.0)
    compat.clear_light_exposure(light)
    compat.normalize_area_power(light)
    light.use_shadow = True
    if kind in {"POINT", "SPOT"}:
        light.shadow_soft_size = 0.0
        light.use_soft_falloff = False
    for key, value in props.items():
        setattr(light, key, value)
    obj = _link(bpy.data.objects.new(name, light))
    obj.location = location
    _look_at(obj, Vector(location) + Vector(direction))
    return obj


# ---------------------------------------------------------------------------------------- materials

def _material(name: str, color=(0.0, 0.0, 0.0), image=None, emission: float = 0.0, specular_level: float = 0.0,
              roughness: float = 1.0):
    """Principled BSDF made pure Lambert by default: no specular layer (Specular IOR Level 0 removes the
    ~3 % it takes from the diffuse lobe), roughness 1, metallic 0. Base colour from `color` or `image`.
    `specular_level` > 0 adds the dielectric glossy layer (IOR 1.5: F0 = 0.08 x level) of `roughness`."""
    mat = bpy.data.materials.new(name)
    bsdf = compat.node_tree(mat).nodes["Principled BSDF"]
    bsdf.inputs["Base Color"].default_value = (*color, 1.0)
    bsdf.inputs["Metallic"].default_value = 0.0
    bsdf.inputs["Roughness"].default_value = roughness
    bsdf.inputs["IOR"].default_value = 1.5
    bsdf.inputs["Specular IOR Level"].default_value = specular_level
    if image is not None:
        tex = mat.node_tree.nodes.new("ShaderNodeTexImage")
        tex.image = image
        tex.interpolation = "Closest"  # exact per-texel albedo, the same in Cycles and a GPU fetch
        mat.node_tree.links.new(tex.outputs["Color"], bsdf.inputs["Base Color"])
    if emission:
        bsdf.inputs["Emission Color"].default_value = (1.0, 1.0, 1.0, 1.0)
        bsdf.inputs["Emission Strength"].default_value = emission
    mat.diffuse_color = (*color, 1.0)  # the solid-viewport colour, for people looking at the file
    return mat


def _checker_image():
    """256^2 linear float checker (8 x 8 squares, Cornell white / 30 % of it) times a ramp along u,
    so orientation errors show. Packed into the .blend (as EXR) so the file is self-contained."""
    n, squares = 256, 8
    i = np.arange(n)
    cell = i * squares // n
    checker = np.where((cell[None, :] + cell[:, None]) % 2 == 0, 1.0, 0.3)  # [row v, column u]
    ramp = 0.6 + 0.4 * i[None, :] / (n - 1)
    rgb = (checker * ramp)[..., None] * np.array(WHITE)
    rgba = np.concatenate([rgb, np.ones((n, n, 1))], axis=-1).astype(np.float32)
    img = bpy.data.images.new("Checker", n, n, float_buffer=True)  # linear (Linear Rec.709)
    img.pixels.foreach_set(rgba.ravel())  # row 0 is v = 0 (bottom), as in Blender
    img.pack()
    return img


# ------------------------------------------------------------------------------------------ meshes

def _mesh(name: str, verts, faces, uvs, mat, location=(0.0, 0.0, 0.0), rot_z_deg: float = 0.0):
    """Mesh object with one material and a UV map (`uvs`: one (u, v) per face corner, in face order),
    so every scene can be baked and textured."""
    me = bpy.data.meshes.new(name)
    me.from_pydata([tuple(map(float, v)) for v in verts], [], [tuple(f) for f in faces])
    me.uv_layers.new(name="UVMap").data.foreach_set("uv", np.asarray(uvs, np.float32).ravel())
    me.materials.append(mat)
    me.validate()
    me.update()
    obj = _link(bpy.data.objects.new(name, me))
    obj.location = location
    obj.rotation_euler = (0.0, 0.0, math.radians(rot_z_deg))
    return obj


def _rect(name: str, origin, u, v, mat, hole=None):
    """Rectangle origin + s*u + t*v, s, t in [0, 1], normal along u x v. `hole` = ((s0, s1), (t0, t1))
    cuts an opening: the rectangle becomes the 8 cells around it of a 3 x 3 split. UV = (s, t)."""
    cuts_s, cuts_t = ([0.0, *hole[0], 1.0], [0.0, *hole[1], 1.0]) if hole else ([0.0, 1.0], [0.0, 1.0])
    o, u, v = (np.asarray(x, float) for x in (origin, u, v))
    params = [(s, t) for t in cuts_t for s in cuts_s]
    verts = [o + s * u + t * v for s, t in params]
    ns, faces = len(cuts_s), []
    for j in range(len(cuts_t) - 1):
        for i in range(ns - 1):
            if hole and (i, j) == (1, 1):
                continue
            faces.append((j * ns + i, j * ns + i + 1, (j + 1) * ns + i + 1, (j + 1) * ns + i))
    uvs = [params[k] for f in faces for k in f]
    return _mesh(name, verts, faces, uvs, mat)


# Closed unit box around the origin, outward normals; vertex k has coordinates from bits (x, y, z) of k.
_BOX_VERTS = np.array([[(k >> a) & 1 for a in range(3)] for k in range(8)], float) - 0.5
_BOX_FACES = [(0, 2, 3, 1), (4, 5, 7, 6), (0, 1, 5, 4), (2, 6, 7, 3), (0, 4, 6, 2), (1, 3, 7, 5)]
# UVs: each face in its own cell of a 3 x 3 grid with a margin, so a bake does not overlap itself.
_BOX_UVS = [
    ((f % 3 + 0.05 + 0.9 * s) / 3, (f // 3 + 0.05 + 0.9 * t) / 3)
    for f in range(6)
    for s, t in ((0, 0), (1, 0), (1, 1), (0, 1))
]


def _box(name: str, size, mat, location, rot_z_deg: float = 0.0):
    return _mesh(name, _BOX_VERTS * np.asarray(size, float), _BOX_FACES, _BOX_UVS, mat, location, rot_z_deg)


def _solid(name: str, lo, hi, mat):
    """Axis-aligned closed box from corner lo to corner hi."""
    lo, hi = np.asarray(lo, float), np.asarray(hi, float)
    return _box(name, hi - lo, mat, (lo + hi) / 2)


_SIDES = {"West": (0, 0), "East": (0, 1), "South": (1, 0), "North": (1, 1)}  # axis, low/high


def _shell(prefix: str, lo, hi, mat, skip=(), t: float = SHELL):
    """Closed room of solid walls t thick around the interior box lo..hi. The pieces partition the
    shell without overlaps: walls at +-x cover the corners, +-y walls span the interior x, floor and
    ceiling the interior x and y. `skip` leaves out whole sides (a shared wall, or a wall with an
    opening, built by the caller). Returns {side: (lo, hi)} of every wall, built or skipped."""
    lo, hi = np.asarray(lo, float), np.asarray(hi, float)
    pieces = {}
    for side, (axis, high) in _SIDES.items():
        a, b = lo.copy(), hi.copy()
        a[axis], b[axis] = (hi[axis], hi[axis] + t) if high else (lo[axis] - t, lo[axis])
        a[2], b[2] = lo[2] - t, hi[2] + t
        if axis == 0:
            a[1], b[1] = lo[1] - t, hi[1] + t
        pieces[f"{side}Wall"] = (a, b)
    pieces["Floor"] = (np.array([lo[0], lo[1], lo[2] - t]), np.array([hi[0], hi[1], lo[2]]))
    pieces["Ceiling"] = (np.array([lo[0], lo[1], hi[2]]), np.array([hi[0], hi[1], hi[2] + t]))
    for side, (a, b) in pieces.items():
        if side not in skip:
            _solid(f"{prefix}{side}", a, b, mat)
    return pieces


def _wall_with_opening(name: str, lo, hi, axis_a: int, axis_b: int, opening_a, opening_b, mat):
    """Solid wall lo..hi with a rectangular hole through it, opening_a x opening_b in the wall's two
    in-plane axes: four solids (Below, Above, Left, Right) that close around the hole exactly."""
    lo, hi = np.asarray(lo, float), np.asarray(hi, float)
    (a0, a1), (b0, b1) = opening_a, opening_b
    parts = {
        "Below": ((None, None), (None, b0)),
        "Above": ((None, None), (b1, None)),
        "Left": ((None, a0), (b0, b1)),
        "Right": ((a1, None), (b0, b1)),
    }
    for part, ((pa0, pa1), (pb0, pb1)) in parts.items():
        p, q = lo.copy(), hi.copy()
        for axis, x0, x1 in ((axis_a, pa0, pa1), (axis_b, pb0, pb1)):
            p[axis] = lo[axis] if x0 is None else x0
            q[axis] = hi[axis] if x1 is None else x1
        _solid(f"{name}.{part}", p, q, mat)


# ------------------------------------------------------------------------------------- the scenes

def _cornell(name: str, ceiling_hole=None, textured: bool = False, overhang: float = 0.0,
             glossy: bool = False) -> None:
    """Cornell box: interior x, y in [-1, 1], z in [0, 2], open at y = -1 where the camera looks in.
    Walls are single-sided rectangles meeting exactly at their edges, normals into the room.
    `textured`: floor and back wall take their albedo from a packed checker image. `overhang` extends
    the ceiling past the side and back walls: a sun above the box must not slip through the exactly
    coincident edges (both Cycles and a shadow map leak a pixel-wide line there)."""
    _reset(name, (256, 256))
    white = _material("White", WHITE)
    red, green = _material("Red", RED), _material("Green", GREEN)
    floor_mat = back_mat = _material("Checker", WHITE, image=_checker_image()) if textured else white
    box_mat = white
    if glossy:  # F0 0.08: a polished floor, satin boxes
        floor_mat = _material("GlossyFloor", WHITE, specular_level=1.0, roughness=0.2)
        box_mat = _material("SatinBox", WHITE, specular_level=1.0, roughness=0.45)
    _rect("Floor", (-1, -1, 0), (2, 0, 0), (0, 2, 0), floor_mat)
    o = overhang
    _rect("Ceiling", (-1 - o, -1, 2), (0, 2 + o, 0), (2 + 2 * o, 0, 0), white, hole=ceiling_hole)
    _rect("BackWall", (-1, 1, 0), (2, 0, 0), (0, 0, 2), back_mat)
    _rect("LeftWall", (-1, -1, 0), (0, 2, 0), (0, 0, 2), red)
    _rect("RightWall", (1, -1, 0), (0, 0, 2), (0, 2, 0), green)
    _box("ShortBox", (0.6, 0.6, 0.6), box_mat, (0.33, -0.3, 0.3), rot_z_deg=-17.0)
    _box("TallBox", (0.6, 0.6, 1.2), box_mat, (-0.33, 0.3, 0.6), rot_z_deg=17.0)
    # atan(1 / 2.4) = 22.6 deg: a 45 deg view from y = -3.4 just fills the frame with the open face.
    _camera((0.0, -3.4, 1.0), (0.0, 0.0, 1.0), 45.0)


def _cornell_spot(name: str = "cornell", **kw) -> None:
    _cornell(name, **kw)
    _light("Spot", "SPOT", (0.0, 0.0, 1.95), SPOT_POWER_W,
           spot_size=math.radians(SPOT_SIZE_DEG), spot_blend=SPOT_BLEND, show_cone=False)


def build_cornell() -> None:
    _cornell_spot()


def build_cornell_sun() -> None:
    """Sun through a 0.8 x 0.8 m hole in the ceiling's centre, tilted ~19 deg towards the open front so
    its ~0.8 m lit patch lands on the front of the floor where the camera sees it (a vertical sun's
    patch hides behind the boxes)."""
    _cornell("cornell-sun", ceiling_hole=((0.3, 0.7), (0.3, 0.7)), overhang=0.05)
    _light("Sun", "SUN", (0.0, 0.0, 4.0), 3.0, direction=(0.0, -0.35, -1.0), angle=0.0)


def build_cornell_point() -> None:
    _cornell("cornell-point")
    _light("Point", "POINT", (0.0, 0.0, 1.7), 200.0)


def build_cornell_area() -> None:
    _cornell("cornell-area")
    _light("Area", "AREA", (0.0, 0.0, 1.98), 100.0, shape="SQUARE", size=0.5, spread=math.pi)


def build_cornell_large_area() -> None:
    """A 1 x 1 m square area light (200 W) 2 cm under the ceiling: half the box's width, so near it the
    light's shape matters (a point at its centre is far too bright below it and casts hard shadows)."""
    _cornell("cornell-large-area")
    _light("Area", "AREA", (0.0, 0.0, 1.98), 200.0, shape="SQUARE", size=1.0, spread=math.pi)


def _world(color=(0.0, 0.0, 0.0), strength: float = 1.0, sky: bool = False, sun_disc: bool = False) -> None:
    """The scene's world: a constant colour x strength, or (sky) a Sky Texture x strength, without its
    sun disc (the scene's own SUN lamp is the sun; the sky's own sun where the node puts it by default)
    or, `sun_disc`, with it, the sky's sun along WINDOW_SUN_DIR."""
    world = bpy.context.scene.world
    tree = compat.node_tree(world)
    background = tree.nodes["Background"]
    background.inputs["Color"].default_value = (*color, 1.0)
    background.inputs["Strength"].default_value = strength
    if sky:
        tex = tree.nodes.new("ShaderNodeTexSky")
        tex.sun_disc = sun_disc
        if sun_disc:
            toward = -np.asarray(WINDOW_SUN_DIR, float) / np.linalg.norm(WINDOW_SUN_DIR)
            # world_capture.sun_direction: elevation, then rotation about +z from +y towards +x
            tex.sun_elevation = float(np.arcsin(toward[2]))
            tex.sun_rotation = float(np.arctan2(toward[0], toward[1]))
        tree.links.new(tex.outputs["Color"], background.inputs["Color"])


def build_cornell_grey_world() -> None:
    """The spot-lit Cornell box under Blender's default world, a uniform grey 0.05: it enters through the
    open front and lights the box besides the spot (7 % of the direct light in Cycles)."""
    _cornell_spot("cornell-grey-world")
    _world((0.05, 0.05, 0.05))


def build_window_sky() -> None:
    """window-room lit by its sun and a sky (Sky Texture, no sun disc) through the window: the sky's
    light enters at every angle the opening allows, the sun's as one patch on the floor."""
    build_window_room()
    bpy.context.scene["bounce_scene"] = "window-sky"
    _world(strength=1.0, sky=True)


def build_window_sky_sun() -> None:
    """window-room lit by Blender's Sky Texture alone, as artists light with it: its sun disc is the
    sun (along window-room's sun, through the window), no lamp."""
    build_window_room()
    bpy.data.objects.remove(bpy.data.objects["Sun"])
    bpy.context.scene["bounce_scene"] = "window-sky-sun"
    _world(strength=1.0, sky=True, sun_disc=True)


def build_textured() -> None:
    """The spot-lit Cornell box with an image-textured floor and back wall (UVs span each wall)."""
    _cornell_spot("textured", textured=True)


def build_cornell_glossy() -> None:
    """The spot-lit Cornell box with a polished floor (F0 0.08, roughness 0.2) and satin boxes (0.45):
    the scene of the `vct` method's glossy product (reference --glossy)."""
    _cornell_spot("cornell-glossy", glossy=True)


def build_emissive() -> None:
    """Lit only by a 0.5 x 0.5 m emissive quad 2 cm below the ceiling, facing down. Cycles emits from
    both sides of a mesh, so the ceiling right above it is lit too; an engine must do the same."""
    _cornell("emissive")
    panel = _material("Emitter", (0.0, 0.0, 0.0), emission=20.0)
    _rect("EmissivePanel", (-0.25, -0.25, 1.98), (0, 0.5, 0), (0.5, 0, 0), panel)


def build_window_room() -> None:
    """Closed 4 x 4 x 2.5 m room of 0.1 m solid walls, a 1 x 1 m window in the north wall, a sun at
    45 degrees through it onto the floor (lit patch x in [-0.5, 0.5], y in [0.1, 1.0]: the wall's
    depth trims it). Everything else is lit by bounces only."""
    _reset("window-room", (256, 256))
    white = _material("White", WHITE)
    walls = _shell("", (-2.0, -2.0, 0.0), (2.0, 2.0, 2.5), white, skip={"NorthWall"})
    _wall_with_opening("NorthWall", *walls["NorthWall"], 0, 2, WINDOW_X, WINDOW_Z, white)
    _light("Sun", "SUN", (0.0, 6.0, 6.0), 5.0, direction=WINDOW_SUN_DIR, angle=0.0)
    # From the north-east corner, looking past the lit patch towards the far (south) wall.
    _camera((1.8, 1.8, 1.6), (-0.5, -1.2, 0.5), 75.0)


def build_thin_wall() -> None:
    """Two closed 2 x 2 x 2 m rooms side by side, sharing a wall THIN_WALL thick; a 200 W point light
    in the left (west) room only. The camera looks down from above; both ceilings are hidden from
    camera rays (they still block and reflect light), so both floors are seen."""
    _reset("thin-wall", (256, 128))
    white = _material("White", WHITE)
    h = THIN_WALL / 2
    _shell("Left.", (-2 - h, -1, 0), (-h, 1, 2), white, skip={"EastWall"})
    _shell("Right.", (h, -1, 0), (2 + h, 1, 2), white, skip={"WestWall"})
    # Fills the gap between the two shells exactly, corners included: no path around it.
    _solid("SharedWall", (-h, -1 - SHELL, -SHELL), (h, 1 + SHELL, 2 + SHELL), white)
    for obj in bpy.context.scene.objects:
        if obj.name.endswith("Ceiling"):
            obj.visible_camera = False
    _light("Point", "POINT", (-1 - h, 0.0, 1.7), 200.0)
    _camera((0.0, 0.0, 7.0), (0.0, 0.0, 0.0), 50.0)


SCENES = {
    "cornell": build_cornell,
    "cornell-sun": build_cornell_sun,
    "cornell-point": build_cornell_point,
    "cornell-area": build_cornell_area,
    "cornell-large-area": build_cornell_large_area,
    "cornell-grey-world": build_cornell_grey_world,
    "window-sky": build_window_sky,
    "window-sky-sun": build_window_sky_sun,
    "cornell-glossy": build_cornell_glossy,
    "textured": build_textured,
    "window-room": build_window_room,
    "thin-wall": build_thin_wall,
    "emissive": build_emissive,
}


def build(name: str) -> None:
    """Replace the current file with the named scene."""
    if name not in SCENES:
        raise ConfigError(f"unknown scene {name!r}; known: {', '.join(SCENES)}")
    SCENES[name]()
    bpy.context.view_layer.update()  # so matrix_world is current for callers reading the scene


def save(name: str, path) -> None:
    """Build the named scene and write it (packed images included) to path."""
    build(name)
    try:
        bpy.ops.wm.save_as_mainfile(filepath=str(path), check_existing=False)
    except RuntimeError as exc:
        reason = str(exc).strip().splitlines()[-1] if str(exc).strip() else "save failed"
        raise SceneError(f"cannot write {path}: {reason}") from None
