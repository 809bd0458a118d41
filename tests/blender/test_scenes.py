"""Procedural benchmark scenes (addon/bridge/scenes.py) and `python -m addon scene`."""

from __future__ import annotations

import hashlib
import math
import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

pytestmark = pytest.mark.blender
bpy = pytest.importorskip("bpy")

from bpy_extras.object_utils import world_to_camera_view  # noqa: E402  (after the skip)
from mathutils import Vector  # noqa: E402

from addon import cli  # noqa: E402
from addon.bridge import scenes  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]
CORNELL = {"Floor", "Ceiling", "BackWall", "LeftWall", "RightWall", "ShortBox", "TallBox", "Camera"}
ROOM = {"Floor", "Ceiling", "WestWall", "EastWall", "SouthWall"}
EXPECTED_OBJECTS = {
    "cornell": CORNELL | {"Spot"},
    "cornell-sun": CORNELL | {"Sun"},
    "cornell-point": CORNELL | {"Point"},
    "cornell-area": CORNELL | {"Area"},
    "cornell-large-area": CORNELL | {"Area"},
    "cornell-glossy": CORNELL | {"Spot"},
    "textured": CORNELL | {"Spot"},
    "emissive": CORNELL | {"EmissivePanel"},
    "window-room": ROOM | {f"NorthWall.{p}" for p in ("Below", "Above", "Left", "Right")} | {"Sun", "Camera"},
    "window-sky": ROOM | {f"NorthWall.{p}" for p in ("Below", "Above", "Left", "Right")} | {"Sun", "Camera"},
    "window-sky-sun": ROOM | {f"NorthWall.{p}" for p in ("Below", "Above", "Left", "Right")} | {"Camera"},
    "cornell-grey-world": CORNELL | {"Spot"},
    "thin-wall": {f"Left.{n}" for n in ROOM - {"EastWall"} | {"NorthWall"}}
    | {f"Right.{n}" for n in ROOM - {"WestWall"} | {"NorthWall"}}
    | {"SharedWall", "Point", "Camera"},
}
CORNELL_WALLS = {"Floor", "Ceiling", "BackWall", "LeftWall", "RightWall"}  # open rectangles, not solids


def _mesh_objects():
    return [o for o in bpy.context.scene.objects if o.type == "MESH"]


def _world_mesh(obj):
    """World-space vertices and polygons (index tuples) of the evaluated mesh."""
    ev = obj.evaluated_get(bpy.context.evaluated_depsgraph_get())
    me = ev.to_mesh()
    co = np.empty(len(me.vertices) * 3)
    me.vertices.foreach_get("co", co)
    m = np.array(ev.matrix_world)
    verts = co.reshape(-1, 3) @ m[:3, :3].T + m[:3, 3]
    polys = [tuple(p.vertices) for p in me.polygons]
    ev.to_mesh_clear()
    return verts, polys


def _scene_hash() -> str:
    """Hash of everything a method reads: evaluated vertex positions, light and camera settings,
    material colours and the world, in a fixed (name-sorted) order."""
    h = hashlib.sha256()
    scene = bpy.context.scene
    for obj in sorted(scene.objects, key=lambda o: o.name):
        h.update(obj.name.encode())
        h.update(np.array(obj.matrix_world, np.float64).tobytes())
        if obj.type == "MESH":
            h.update(np.round(_world_mesh(obj)[0], 9).tobytes())
        elif obj.type == "LIGHT":
            d = obj.data
            h.update(repr((d.type, d.energy, tuple(d.color), d.shadow_soft_size)).encode())
            h.update(repr([getattr(d, k) for k in ("spot_size", "spot_blend", "size", "angle") if hasattr(d, k)])
                     .encode())
        elif obj.type == "CAMERA":
            h.update(repr((obj.data.angle, obj.data.type)).encode())
    for mat in sorted(bpy.data.materials, key=lambda m: m.name):
        for inp in mat.node_tree.nodes["Principled BSDF"].inputs:
            if hasattr(inp, "default_value"):
                h.update(repr(np.array(inp.default_value).tolist()).encode())
    h.update(repr((scene.render.resolution_x, scene.render.resolution_y, tuple(scene.world.color))).encode())
    background = scene.world.node_tree.nodes["Background"].inputs
    h.update(repr((tuple(background["Color"].default_value), background["Strength"].default_value,
                   background["Color"].is_linked)).encode())
    return h.hexdigest()


def _fibonacci_dirs(n: int = 200) -> np.ndarray:
    """Deterministic, near-uniform directions on the sphere."""
    i = np.arange(n) + 0.5
    z = 1 - 2 * i / n
    phi = i * math.pi * (3 - math.sqrt(5))
    r = np.sqrt(1 - z * z)
    return np.stack([r * np.cos(phi), r * np.sin(phi), z], axis=1)


def _cast(origin, direction):
    scene = bpy.context.scene
    hit, loc, _n, _i, obj, _m = scene.ray_cast(bpy.context.evaluated_depsgraph_get(), origin, direction)
    return hit, np.array(loc), obj


def _exit_face(origin, d, lo, hi):
    """(axis, side) of the face of box lo..hi through which a ray from inside it leaves."""
    with np.errstate(divide="ignore"):
        t = np.where(d > 0, (np.asarray(hi) - origin) / d, (np.asarray(lo) - origin) / d)
    axis = int(np.argmin(t))
    return axis, int(d[axis] > 0), origin + t[axis] * d


def _closed_volume(verts, polys) -> float:
    """Signed volume (divergence theorem); the caller checks the mesh is closed."""
    vol = 0.0
    for p in polys:
        for k in range(1, len(p) - 1):
            vol += np.dot(verts[p[0]], np.cross(verts[p[k]], verts[p[k + 1]])) / 6
    return vol


def _is_closed(polys) -> bool:
    edges: dict[tuple[int, int], int] = {}
    for p in polys:
        for a, b in zip(p, p[1:] + p[:1], strict=True):
            edges[(min(a, b), max(a, b))] = edges.get((min(a, b), max(a, b)), 0) + 1
    return all(c == 2 for c in edges.values())


# --------------------------------------------------------------------------------- every scene

@pytest.mark.parametrize("name", list(scenes.SCENES))
def test_scene_builds_complete(fresh_blend, name):
    t0 = time.perf_counter()
    scenes.build(name)
    assert time.perf_counter() - t0 < 10.0
    scene = bpy.context.scene
    assert scene["bounce_scene"] == name
    assert {o.name for o in scene.objects} == EXPECTED_OBJECTS[name]
    assert scene.camera is not None and scene.camera.type == "CAMERA"
    assert scene.render.resolution_percentage == 100 and scene.unit_settings.scale_length == 1.0
    # A black world but where the scene is about the world: Blender's default grey, a sky.
    background = scene.world.node_tree.nodes["Background"].inputs
    if name == "cornell-grey-world":
        assert tuple(background["Color"].default_value)[:3] == pytest.approx((0.05,) * 3)
        assert background["Strength"].default_value == 1.0
    elif name in ("window-sky", "window-sky-sun"):
        assert background["Color"].is_linked and background["Strength"].default_value == 1.0
    else:
        assert background["Strength"].default_value == 0.0

    lamps = [o.data for o in scene.objects if o.type == "LIGHT"]
    emitters = [m for m in bpy.data.materials
                if m.node_tree.nodes["Principled BSDF"].inputs["Emission Strength"].default_value > 0]
    # Exactly one source: the benchmark's stated light (window-sky-sun's is its sky's sun disc).
    assert len(lamps) + len(emitters) == (0 if name == "window-sky-sun" else 1)
    for light in lamps:
        assert tuple(light.color) == (1.0, 1.0, 1.0) and light.energy > 0
        if light.type in {"POINT", "SPOT"}:
            assert light.shadow_soft_size == 0.0  # a true point light, as an RSM models it
    # Pure Lambert (what Cycles' Diffuse passes compare with), but cornell-glossy's glossy layers.
    glossy = {"GlossyFloor": (1.0, 0.2), "SatinBox": (1.0, 0.45)} if name == "cornell-glossy" else {}
    for mat in bpy.data.materials:
        bsdf = mat.node_tree.nodes["Principled BSDF"].inputs
        level, roughness = glossy.get(mat.name, (0.0, 1.0))
        assert bsdf["Specular IOR Level"].default_value == level
        assert bsdf["Roughness"].default_value == pytest.approx(roughness)
        assert bsdf["Metallic"].default_value == 0.0

    for obj in _mesh_objects():
        assert len(obj.data.uv_layers) == 1, obj.name  # bakes and textures need UVs everywhere
        assert len(obj.data.materials) == 1 and obj.data.materials[0] is not None
        verts, polys = _world_mesh(obj)
        normals = np.array([p.normal for p in obj.data.polygons]) @ np.array(obj.matrix_world)[:3, :3].T
        centres = np.array([verts[list(p)].mean(axis=0) for p in polys])
        if "ShortBox" in EXPECTED_OBJECTS[name] and obj.name in CORNELL_WALLS | {"EmissivePanel"}:
            # Open rectangles of the Cornell box: every face looks into the room (centre (0, 0, 1)).
            assert np.all(np.sum(normals * ((0, 0, 1) - centres), axis=1) > 0), obj.name
        else:
            # Solids: closed, positive volume, every face looking out of the object.
            assert _is_closed(polys) and _closed_volume(verts, polys) > 0, obj.name
            assert np.all(np.sum(normals * (centres - verts.mean(axis=0)), axis=1) > 0), obj.name


@pytest.mark.parametrize("name", list(scenes.SCENES))
def test_scene_is_deterministic(fresh_blend, name):
    scenes.build(name)
    first = _scene_hash()
    scenes.build(name)
    assert _scene_hash() == first


def test_scenes_differ(fresh_blend):
    hashes = set()
    for name in scenes.SCENES:
        scenes.build(name)
        hashes.add(_scene_hash())
    assert len(hashes) == len(scenes.SCENES)  # the hash sees lights, textures' absence and geometry


def test_stated_light_settings(fresh_blend):
    scenes.build("cornell")
    spot = bpy.data.objects["Spot"]
    assert spot.data.energy == 300.0 and spot.data.spot_blend == pytest.approx(0.15)
    assert math.degrees(spot.data.spot_size) == pytest.approx(70.0)
    assert tuple(spot.location) == pytest.approx((0, 0, 1.95))
    assert np.allclose(np.array(spot.matrix_world)[:3, 2], (0, 0, 1), atol=1e-6)  # local -Z (emission) is down
    scenes.build("cornell-area")
    area = bpy.data.objects["Area"]
    assert (area.data.shape, area.data.size, area.data.energy) == ("SQUARE", 0.5, 100.0)
    assert area.location.z == pytest.approx(1.98)
    assert np.allclose(np.array(area.matrix_world)[:3, 2], (0, 0, 1), atol=1e-6)  # facing down
    scenes.build("emissive")
    verts, _ = _world_mesh(bpy.data.objects["EmissivePanel"])
    assert np.ptp(verts, axis=0) == pytest.approx((0.5, 0.5, 0.0))


# ------------------------------------------------------------------------- closed and open walls

@pytest.mark.parametrize("origin", [(0, -0.5, 1.5), (0.6, 0.6, 1.6), (-0.7, -0.6, 0.4)])
def test_cornell_closed_except_front(fresh_blend, origin):
    scenes.build("cornell")
    origin, escaped = np.array(origin, float), 0
    for d in _fibonacci_dirs():
        hit, _, _ = _cast(origin, d)
        axis, high, _ = _exit_face(origin, d, (-1, -1, 0), (1, 1, 2))
        if (axis, high) != (1, 0):  # not leaving through the open front (y = -1)
            assert hit, d
        escaped += not hit
    assert escaped > 0  # the front really is open


def test_cornell_sun_hole(fresh_blend):
    scenes.build("cornell-sun")
    assert not _cast((0.0, 0.0, 1.0), (0, 0, 1))[0]  # up through the 0.8 m hole
    assert not _cast((0.35, 0.0, 1.0), (0, 0, 1))[0]  # still inside it (hole spans |x| < 0.4)
    assert _cast((0.45, 0.0, 1.0), (0, 0, 1))[0]  # just beside it: ceiling
    assert _cast((-1.0, 0.0, 1.9), (-1, 0, 1))[0]  # the overhang closes the wall/ceiling edge
    sun = bpy.data.objects["Sun"]
    assert sun.data.energy == 3.0 and sun.data.angle == 0.0
    towards_sun = np.array(sun.matrix_world)[:3, 2]
    assert np.allclose(towards_sun, np.array([0.0, 0.35, 1.0]) / np.hypot(0.35, 1.0), atol=1e-6)


@pytest.mark.parametrize("origin", [(0, 0, 1.25), (1.5, -1.5, 0.3), (-1.2, 1.5, 2.2)])
def test_window_room_closed_except_window(fresh_blend, origin):
    scenes.build("window-room")
    origin = np.array(origin, float)
    (x0, x1), (z0, z1) = scenes.WINDOW_X, scenes.WINDOW_Z
    for d in _fibonacci_dirs(400):
        hit, _, _ = _cast(origin, d)
        axis, high, at = _exit_face(origin, d, (-2, -2, 0), (2, 2, 2.5))
        through_window = (axis, high) == (1, 1) and x0 - 0.05 < at[0] < x1 + 0.05 and z0 - 0.05 < at[2] < z1 + 0.05
        if not through_window:
            assert hit, d
    assert not _cast(origin, np.array([0, 2, 1.5]) - origin)[0]  # the window is open


def test_window_room_sun_lights_floor_and_camera_sees_it(fresh_blend):
    scenes.build("window-room")
    sun = bpy.data.objects["Sun"]
    to_sun = np.array(sun.matrix_world)[:3, 2]  # local +Z: opposite to the light's travel
    assert np.allclose(to_sun, -np.array(scenes.WINDOW_SUN_DIR) / math.sqrt(2), atol=1e-6)
    assert sun.data.energy == 5.0 and sun.data.angle == 0.0
    lit, shaded = (0.0, 0.55, 0.001), (0.0, -1.0, 0.001)
    assert not _cast(lit, to_sun)[0]  # the patch sees the sun through the window
    assert _cast(shaded, to_sun)[0]  # the rest of the floor does not
    scene = bpy.context.scene
    for point in (lit, (0.0, -2.0, 1.25)):  # lit patch and the far wall's centre are in the frame
        u, v, depth = world_to_camera_view(scene, scene.camera, Vector(point))
        assert 0 < u < 1 and 0 < v < 1 and depth > 0, point
        hit, loc, _ = _cast(scene.camera.location, np.array(point) - np.array(scene.camera.location))
        assert hit and np.allclose(loc, point, atol=0.01)  # and not hidden behind anything


@pytest.mark.parametrize("side", [-1, 1])
def test_thin_wall_rooms_are_sealed(fresh_blend, side):
    scenes.build("thin-wall")
    h = scenes.THIN_WALL / 2
    for origin in ((side * 1.03, 0.0, 1.0), (side * 0.2, 0.9, 0.1), (side * 1.9, -0.9, 1.9)):
        for d in _fibonacci_dirs():
            hit, loc, _ = _cast(np.array(origin), d)
            assert hit, (origin, d)
            assert side * loc[0] >= h - 1e-5, (origin, d, loc)  # never past the shared wall
    light = bpy.data.objects["Point"]
    assert light.location.x < -h and light.data.energy == 200.0
    hit, _, obj = _cast(light.location, np.array((1.0, 0.0, 0.0)))
    assert hit and obj.name == "SharedWall"


def test_thin_wall_camera_sees_both_floors(fresh_blend):
    scenes.build("thin-wall")
    scene = bpy.context.scene
    assert all(o.visible_camera != o.name.endswith("Ceiling") for o in _mesh_objects())
    for floor in ("Left.Floor", "Right.Floor"):
        verts, _ = _world_mesh(bpy.data.objects[floor])
        top = verts[verts[:, 2] > -1e-6]  # the floor's upper face corners
        for corner in top:
            u, v, depth = world_to_camera_view(scene, scene.camera, Vector(corner))
            assert 0 < u < 1 and 0 < v < 1 and depth > 0, (floor, corner)
    width = np.ptp(_world_mesh(bpy.data.objects["SharedWall"])[0][:, 0])
    assert width == pytest.approx(scenes.THIN_WALL)


@pytest.mark.parametrize(
    ("name", "expected"),
    [
        # Solids partition the shell exactly (no overlap): outer box - interior - window hole.
        ("window-room", 4.2 * 4.2 * 2.7 - 4 * 4 * 2.5 - 1 * 1 * 0.1),
        ("thin-wall", (4 + scenes.THIN_WALL + 0.2) * 2.2 * 2.2 - 2 * 8.0),
    ],
)
def test_shell_volume(fresh_blend, name, expected):
    scenes.build(name)
    total = sum(_closed_volume(*_world_mesh(o)) for o in _mesh_objects())
    assert total == pytest.approx(expected, rel=1e-5)


def test_textured_image_packed(fresh_blend):
    scenes.build("textured")
    (img,) = bpy.data.images
    assert img.packed_file is not None and img.size[:] == (256, 256)
    px = np.empty(256 * 256 * 4, np.float32)
    img.pixels.foreach_get(px)
    rgb = px.reshape(256, 256, 4)[..., :3]
    assert rgb.max() <= max(scenes.WHITE) + 1e-6 and rgb.min() > 0  # a valid albedo everywhere
    assert len(np.unique(rgb[..., 0].round(4))) > 8  # checker times a ramp, not a flat colour
    for name in ("Floor", "BackWall"):
        nodes = bpy.data.objects[name].data.materials[0].node_tree.nodes
        (tex,) = [n for n in nodes if n.bl_idname == "ShaderNodeTexImage"]
        assert tex.image == img and tex.outputs["Color"].links[0].to_socket.name == "Base Color"


# ----------------------------------------------------------------------------------------- CLI

def test_cli_writes_blend_that_reopens(fresh_blend, tmp_path):
    out = tmp_path / "textured.blend"
    assert cli.main(["scene", "textured", "--out", str(out)]) == 0
    names, digest = {o.name for o in bpy.context.scene.objects}, _scene_hash()
    bpy.ops.wm.read_factory_settings(use_empty=True)
    bpy.ops.wm.open_mainfile(filepath=str(out))
    assert {o.name for o in bpy.context.scene.objects} == names == EXPECTED_OBJECTS["textured"]
    assert _scene_hash() == digest
    assert bpy.data.images["Checker"].packed_file is not None


def test_cli_subprocess(tmp_path):
    """The real entry point: `python -m addon scene` exits 0 and writes the file."""
    out = tmp_path / "cornell.blend"
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    run = subprocess.run([sys.executable, "-m", "addon", "scene", "cornell", "--out", str(out)],
                         cwd=ROOT, env=env, capture_output=True, text=True, timeout=60)
    assert run.returncode == 0, run.stderr
    assert out.is_file() and out.stat().st_size > 0
    run = subprocess.run([sys.executable, "-m", "addon", "scene", "nope", "--out", str(out)],
                         cwd=ROOT, env=env, capture_output=True, text=True, timeout=60)
    assert run.returncode == 2 and len(run.stderr.strip().splitlines()) == 1


def test_cli_list(capsys):
    assert cli.main(["scene", "--list"]) == 0
    assert capsys.readouterr().out.split() == list(scenes.SCENES)


@pytest.mark.parametrize(
    ("argv", "needle"),
    [
        (["scene", "nope", "--out", "{tmp}/x.blend"], "window-room"),  # lists the known names
        (["scene", "--out", "{tmp}/x.blend"], "known"),
        (["scene", "cornell"], "--out"),
        (["scene", "cornell", "--out", "{tmp}/x.png"], ".blend"),
        (["scene", "cornell", "--out", "{tmp}/missing/dir/x.blend"], "no such directory"),
        (["scene", "cornell", "--out", "{tmp}"], ".blend"),
        (["scene", "cornell", "--out", "{tmp}/dir.blend"], "cannot write"),
    ],
)
def test_cli_errors(fresh_blend, tmp_path, capsys, argv, needle):
    (tmp_path / "dir.blend").mkdir()
    argv = [a.replace("{tmp}", str(tmp_path)) for a in argv]
    assert cli.main(argv) == 2
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1 and err.startswith("error: ") and needle in err
    assert not (tmp_path / "x.blend").exists()
