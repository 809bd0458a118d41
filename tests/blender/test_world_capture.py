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
