"""A world that varies with direction, rendered by Cycles into world.py's map layout
(bridge/world_capture.py), and the capture's choice between a constant and a map."""

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
    # Without maps (the interactive viewport) the world lights as its constant part.
    assert SceneCache(world_maps=False).update(bpy.context.evaluated_depsgraph_get(), 8, 8).world_map is None


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
    # 2 % (the render samples each texel's centre, the read averages the pixels in it: a gradient's
    # mean over a texel is its centre value).
    import time

    from addon.bridge import world_capture

    world, _ = _hdri_world()
    assert world_capture._direct_hdri(world) is not None
    t0 = time.perf_counter()
    read = world_capture.world_map(world)
    read_s = time.perf_counter() - t0
    rendered = world_capture._render(world)
    np.testing.assert_allclose(read, rendered, rtol=0.02)
    assert read_s < 0.5, read_s  # a read, not a render (~1.5 s)


def test_hdri_sun_keeps_its_energy(fresh_blend):
    # One pixel 2000 times the sky: a point-sampled map would miss it; the read bins it into one texel
    # with its solid angle, so the map's total power int L dw equals the image's (to float rounding).
    from addon.bridge import world_capture
    from addon.engine.world import directions

    world, image = _hdri_world(hot_pixel=(90, 100), name="HDRI with a sun")
    m = world_capture.world_map(world)
    _, omega = directions(*m.shape[:2])
    h, w = image.shape[:2]
    lat = ((np.arange(h) + 0.5) / h - 0.5) * np.pi  # image rows bottom-up
    band = 2 * np.pi * (np.sin(lat + np.pi / (2 * h)) - np.sin(lat - np.pi / (2 * h))) / w
    expected = np.einsum("ijc,i->c", image, band)
    np.testing.assert_allclose(np.einsum("ijc,ij->c", m, omega), expected, rtol=2e-3)
