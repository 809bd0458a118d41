"""A world that varies with direction, rendered by Cycles into world.py's map layout
(bridge/world_capture.py), and the capture's choice between a constant and a map."""

import math

import numpy as np
import pytest

pytestmark = [pytest.mark.blender, pytest.mark.slow]
bpy = pytest.importorskip("bpy")


def _direction_world():
    """A world whose radiance is its own view direction (Texture Coordinate > Generated, per colour)."""
    world = bpy.data.worlds.new("Directions")
    from addon.bridge import compat

    tree = compat.node_tree(world)
    coord = tree.nodes.new("ShaderNodeTexCoord")
    tree.links.new(coord.outputs["Generated"], tree.nodes["Background"].inputs["Color"])
    tree.nodes["Background"].inputs["Strength"].default_value = 1.0
    return world


def test_map_texels_hold_their_directions(fresh_blend):
    # Every texel's colour is the direction world.py says it looks along (negative parts clamp to 0):
    # the camera's orientation and the mirrored columns are right. 0.03: the half-texel filter width.
    from addon.bridge import world_capture
    from addon.engine.world import directions

    m = world_capture.world_map(_direction_world())
    dirs, _ = directions(*m.shape[:2])
    np.testing.assert_allclose(m, np.maximum(dirs, 0.0), atol=0.03)


def test_a_texel_holds_the_mean_of_its_directions(fresh_blend):
    # A world bright (1) above latitude -0.703125 degrees and black below: the edge cuts the first row
    # of the 64-row map below the horizon (-2.8125..0 degrees) a quarter of the way down. By solid angle
    # a quarter of that row is lit: sin(0.703125) / sin(2.8125) = 0.2501; its 4 sub-rows of samples give
    # 1 of 4 weighted by their bands, 0.2501; the texel's centre alone (-1.4 degrees) would read 0. Rows
    # above read 1 and rows below 0 exactly (every sample lies on one side).
    from addon.bridge import compat, world_capture

    world = bpy.data.worlds.new("Edge")
    tree = compat.node_tree(world)
    coord = tree.nodes.new("ShaderNodeTexCoord")
    xyz = tree.nodes.new("ShaderNodeSeparateXYZ")
    above = tree.nodes.new("ShaderNodeMath")
    above.operation = "GREATER_THAN"
    above.inputs[1].default_value = math.sin(math.radians(-0.703125))
    tree.links.new(coord.outputs["Generated"], xyz.inputs[0])
    tree.links.new(xyz.outputs["Z"], above.inputs[0])
    tree.links.new(above.outputs[0], tree.nodes["Background"].inputs["Color"])
    m = world_capture.world_map(world)
    row = m.shape[0] // 2  # the first row below the horizon
    np.testing.assert_allclose(m[:row], 1.0, atol=1e-6)
    np.testing.assert_allclose(m[row], 0.2501, atol=0.002)
    np.testing.assert_allclose(m[row + 1:], 0.0, atol=1e-6)


def test_map_is_cached_until_the_world_changes(fresh_blend):
    from addon.bridge import world_capture

    world = _direction_world()
    first = world_capture.world_map(world)
    assert world_capture.world_map(world) is first  # no second render
    world.node_tree.nodes["Background"].inputs["Strength"].default_value = 2.0
    np.testing.assert_allclose(world_capture.world_map(world), 2.0 * first, rtol=1e-5, atol=1e-6)


def test_capture_keeps_a_constant_world_constant(fresh_blend):
    from addon.bridge import scenes
    from addon.bridge.capture import SceneCache

    scenes.build("cornell-grey-world")
    scene = SceneCache().update(bpy.context.evaluated_depsgraph_get(), 8, 8)
    assert scene.world_map is None
    np.testing.assert_allclose(scene.world_color, 0.05, rtol=1e-6)
    bpy.context.scene.world = _direction_world()
    scene = SceneCache().update(bpy.context.evaluated_depsgraph_get(), 8, 8)
    assert scene.world_map is not None and scene.world_map.shape[2] == 3
    # Without renders (the interactive viewport) a node tree whose map is not made yet lights as its
    # average, with a warning; once a map was rendered for that node tree, it lights by direction.
    from addon.bridge import world_capture

    world_capture.forget()
    viewport = SceneCache(render_world=False).update(bpy.context.evaluated_depsgraph_get(), 8, 8)
    assert viewport.world_map is None
    assert any("average" in w for w in viewport.warnings)
    rendered = world_capture.world_map(bpy.context.scene.world)
    viewport = SceneCache(render_world=False).update(bpy.context.evaluated_depsgraph_get(), 8, 8)
    assert viewport.world_map is rendered


def _sky_world(elevation=0.45, rotation=0.7):
    """Blender's Sky Texture at its defaults (its sun disc on) with the sun at `elevation` above the
    horizon, turned `rotation` about +z."""
    from addon.bridge import compat

    world = bpy.data.worlds.new("Sky")
    tree = compat.node_tree(world)
    node = tree.nodes.new("ShaderNodeTexSky")
    node.sun_elevation, node.sun_rotation = elevation, rotation
    tree.links.new(node.outputs["Color"], tree.nodes["Background"].inputs["Color"])
    return world, node


def test_a_sky_textures_sun_disc_becomes_a_sun_light(fresh_blend):
    # The disc is half a degree wide, about the spacing of the render's samples (0.7 degrees): a map
    # rendered with it would hit or miss it by chance. The capture renders the map without it and
    # measures the disc as a SUN light along the node's sun direction (the irradiance against Cycles:
    # tests/e2e/test_direct_vs_cycles.py, the sky case); a sun below the horizon gives none.
    from addon.bridge import world_capture

    world, node = _sky_world()
    assert node.sun_disc and node.sky_type in world_capture.DISC_SKIES
    captured = world_capture.capture(world)
    (sun,) = captured.suns
    np.testing.assert_allclose(sun.direction, -world_capture.sun_direction(node), atol=1e-12)
    assert sun.sun_angle_rad == pytest.approx(node.sun_size)
    node.sun_disc = False
    np.testing.assert_array_equal(world_capture._render_map(world), captured.map)
    # The disc's light against the whole sky's on a floor, in luminance: at 26 degrees a clear day's sun
    # is most of it (4.9x the sky's in this model; the bound 3x only says it is no detail).
    from addon.engine.world import LUMA, directions

    d, omega = directions(*captured.map.shape[:2])
    sky_floor = np.einsum("ijc,ij->c", captured.map * np.maximum(d[..., 2:3], 0.0), omega)
    sun_floor = sun.sun_strength * sun.color * math.sin(node.sun_elevation)
    assert sun_floor @ LUMA > 3.0 * (sky_floor @ LUMA), (sun_floor, sky_floor)
    node.sun_disc = True
    node.sun_elevation = -0.2
    assert world_capture.capture(world).suns == ()


def _hdri_world(hot_pixel=None, name="HDRI"):
    """An Environment Texture of a 256 x 128 float image (linear): a sky gradient from dark below to bright
    above (rows are bottom-up in Blender), and optionally one hot pixel (a sun)."""
    from addon.bridge import compat

    w, h = 256, 128
    img = bpy.data.images.new(name, w, h, float_buffer=True)
    img.colorspace_settings.name = "Linear Rec.709"
    rows = np.linspace(0.2, 1.0, h)[:, None, None] * np.ones((h, w, 1))
    px = np.concatenate([rows * [0.4, 0.6, 1.0], np.ones((h, w, 1))], axis=2)
    if hot_pixel is not None:
        px[hot_pixel] = (2000.0, 1800.0, 1500.0, 1.0)
    img.pixels.foreach_set(px.astype(np.float32).ravel())
    world = bpy.data.worlds.new("HDRI")
    tree = compat.node_tree(world)
    env = tree.nodes.new("ShaderNodeTexEnvironment")
    env.image = img
    tree.links.new(env.outputs["Color"], tree.nodes["Background"].inputs["Color"])
    tree.nodes["Background"].inputs["Strength"].default_value = 1.5
    return world, px[..., :3] * 1.5


def test_hdri_is_read_directly_and_agrees_with_cycles(fresh_blend):
    # The direct read (no render) and Cycles' render of the same smooth world agree texel by texel within
    # 2 % (both average each texel's directions; over a linear gradient the read's pixel means and the
    # render's interpolated samples agree). Not in the two pole rows: a map texel there holds the
    # image's two edge rows, and Cycles' lookup interpolates the samples beyond their centres with the
    # image's opposite edge (its extension repeats), 6 % off the pixels' own mean at the bottom.
    import time

    from addon.bridge import world_capture

    world, _ = _hdri_world()
    assert world_capture._direct_hdri(world) is not None
    t0 = time.perf_counter()
    read = world_capture.world_map(world)
    read_s = time.perf_counter() - t0
    rendered = world_capture._render_map(world)
    np.testing.assert_allclose(read[1:-1], rendered[1:-1], rtol=0.02)
    assert read_s < 0.5, read_s  # a read, not a render (~1.5 s)


def test_hdri_sun_becomes_a_sun_and_keeps_its_energy(fresh_blend):
    # One pixel 2000 times the sky: the read takes it out as a sun along that pixel's direction (the
    # pixel kept at 100x the image's median luminance) and bins the rest into the map with each pixel's
    # solid angle, so the map's int L dw plus the sun's irradiance equal the image's (to 2e-3: the read
    # weighs pixels by cos(latitude), the test by the exact band areas).
    from addon.bridge import world_capture
    from addon.engine.world import directions

    world, image = _hdri_world(hot_pixel=(90, 100), name="HDRI with a sun")
    captured = world_capture.capture(world)
    (sun,) = captured.suns
    _, omega = directions(*captured.map.shape[:2])
    h, w = image.shape[:2]
    lat = ((np.arange(h) + 0.5) / h - 0.5) * np.pi  # image rows bottom-up
    band = 2 * np.pi * (np.sin(lat + np.pi / (2 * h)) - np.sin(lat - np.pi / (2 * h))) / w
    expected = np.einsum("ijc,i->c", image, band)
    total = np.einsum("ijc,ij->c", captured.map, omega) + sun.sun_strength * sun.color
    np.testing.assert_allclose(total, expected, rtol=2e-3)
    assert sun.sun_strength > 0.9 * float((image[90, 100] * band[90]).max())  # nearly all of it is the sun
    sun_lat, sun_lon = lat[90], (0.5 - (100 + 0.5) / w) * 2 * np.pi  # that pixel's centre
    toward = [np.cos(sun_lat) * np.cos(sun_lon), np.cos(sun_lat) * np.sin(sun_lon), np.sin(sun_lat)]
    np.testing.assert_allclose(-sun.direction, toward, atol=1e-9)
    # A sky dome whose lower half is black still finds its sun (the level is the lit pixels' median),
    # and an image with no pixel 100x that level has none.
    from addon.bridge.world_capture import _take_sun

    dome = image.copy()
    dome[: h // 2] = 0.0
    solid = np.repeat(band[:, None], w, axis=1)
    lon = (0.5 - (np.arange(w) + 0.5) / w) * 2 * np.pi
    assert len(_take_sun(dome, lat, lon, solid)[1]) == 1
    assert _take_sun(np.where(dome > 100, 1.0, dome), lat, lon, solid)[1] == []


def test_viewport_reads_an_hdri_without_rendering_and_rebins_nothing_for_its_strength(fresh_blend, monkeypatch):
    # The viewport (render_world False) lights an HDRI by direction: read directly, never rendered. Its
    # binning is kept per image, so a new Background strength only scales the map (exactly: the same
    # float32 binning times each strength).
    from addon.bridge import world_capture
    from addon.bridge.capture import SceneCache

    world_capture.forget()
    bins = []
    real_read = world_capture._read_hdri
    monkeypatch.setattr(world_capture, "_read_hdri", lambda image: bins.append(image.name) or real_read(image))
    monkeypatch.setattr(world_capture, "_render", lambda world: pytest.fail("the viewport rendered the world"))
    world, image = _hdri_world()
    bpy.context.scene.world = world
    first = SceneCache(render_world=False).update(bpy.context.evaluated_depsgraph_get(), 8, 8).world_map
    assert first is not None and bins == ["HDRI"]
    world.node_tree.nodes["Background"].inputs["Strength"].default_value = 3.0
    again = SceneCache(render_world=False).update(bpy.context.evaluated_depsgraph_get(), 8, 8).world_map
    assert bins == ["HDRI"]  # no second binning
    np.testing.assert_allclose(again, first * 2.0, rtol=1e-6)  # strength 1.5 -> 3.0


def test_rendering_the_world_keeps_the_users_render_result(fresh_blend):
    # The world is rendered from a scene of its own: the Render Result's active slot, seen from the
    # user's scene, still holds the user's last render afterwards. That render here: a red world seen by
    # a camera, so every pixel is (1, 0, 0) up to Cycles' single sample (atol 0.1).
    import tempfile
    from pathlib import Path

    from addon.bridge import compat, world_capture

    scene = bpy.context.scene
    cam = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
    scene.collection.objects.link(cam)
    scene.camera = cam
    red = bpy.data.worlds.new("Red")
    compat.node_tree(red).nodes["Background"].inputs["Color"].default_value = (1, 0, 0, 1)
    scene.world = red
    scene.render.engine = "CYCLES"
    scene.cycles.samples = 1
    scene.render.resolution_x, scene.render.resolution_y, scene.render.resolution_percentage = 8, 8, 100
    scene.render.image_settings.file_format = "OPEN_EXR"
    bpy.ops.render.render()
    world_capture.forget()
    world_capture.world_map(_direction_world())
    path = Path(tempfile.mkdtemp()) / "user.exr"
    bpy.data.images["Render Result"].save_render(str(path), scene=scene)
    image = bpy.data.images.load(str(path))
    px = np.empty(8 * 8 * 4, np.float32)
    image.pixels.foreach_get(px)
    np.testing.assert_allclose(px.reshape(-1, 4)[:, :3].mean(axis=0), [1.0, 0.0, 0.0], atol=0.1)


def test_a_stored_map_is_saved_with_the_blend_until_the_world_changes(fresh_blend, tmp_path, monkeypatch):
    # Capture World Light keeps the map in the world's custom properties: after saving and opening the
    # file the viewport (no renders) lights by it, to the bit (float32 through float64 and back); an edit
    # of the world makes it stale, and the world lights as its average again.
    from addon.bridge import world_capture
    from addon.bridge.capture import SceneCache

    world, node = _sky_world()
    bpy.context.scene.world = world
    made = world_capture.capture(world)
    assert len(made.suns) == 1
    world_capture.store(world, made)
    path = tmp_path / "sky.blend"
    bpy.ops.wm.save_as_mainfile(filepath=str(path))
    bpy.ops.wm.read_factory_settings(use_empty=True)
    bpy.ops.wm.open_mainfile(filepath=str(path))
    world_capture.forget()
    monkeypatch.setattr(world_capture, "_render", lambda world: pytest.fail("rendered a stored world"))
    scene = SceneCache(render_world=False).update(bpy.context.evaluated_depsgraph_get(), 8, 8)
    np.testing.assert_array_equal(scene.world_map, made.map)
    (sun,) = [light for light in scene.lights if light.kind == "SUN"]
    np.testing.assert_allclose(sun.direction, made.suns[0].direction, atol=1e-12)
    np.testing.assert_allclose(sun.color * sun.sun_strength, made.suns[0].color * made.suns[0].sun_strength, rtol=1e-12)
    bpy.context.scene.world.node_tree.nodes["Background"].inputs["Strength"].default_value = 2.0
    assert SceneCache(render_world=False).update(bpy.context.evaluated_depsgraph_get(), 8, 8).world_map is None
