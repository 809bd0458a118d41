"""The albedo atlas (passes/albedo_atlas.py): every image lands whole, where its rect says, and none
overlaps another; images that do not fit are halved together until they do."""

from __future__ import annotations

import numpy as np

from addon.engine.passes import albedo_atlas
from addon.engine.scene import AlbedoTextures, Scene


def test_images_land_whole_at_their_rects_without_overlap():
    rng = np.random.default_rng(3)
    sizes = [(5, 7), (16, 3), (1, 1), (9, 9), (2, 30)]
    images = [rng.uniform(0, 1, (*s, 3)).astype(np.float32) for s in sizes]
    atlas = albedo_atlas.pack(images, width=32)
    used = np.zeros(atlas.texels.shape[:2], int)
    for image, (x0, y0, w, h) in zip(images, atlas.rects.astype(int), strict=True):
        assert (h, w) == image.shape[:2]
        np.testing.assert_array_equal(atlas.texels[y0:y0 + h, x0:x0 + w, :3], image)
        used[y0:y0 + h, x0:x0 + w] += 1
    assert used.max() == 1
    assert atlas.texels.shape[1] == 32 and atlas.texels.shape[0] <= 32


def test_images_too_large_are_halved_together_by_box_means():
    # Two 8 x 8 images in a 4-wide atlas: halved twice (8 -> 4 fits the width, but 4 + 4 rows of height
    # is over 4, so -> 2), each texel the mean of the 4 x 4 block it covers.
    images = [np.arange(64 * 3, dtype=np.float32).reshape(8, 8, 3) + k for k in (0, 1000)]
    atlas = albedo_atlas.pack(images, width=4)
    for image, (x0, y0, w, h) in zip(images, atlas.rects.astype(int), strict=True):
        assert (w, h) == (2, 2)
        expected = image.reshape(2, 4, 2, 4, 3).mean(axis=(1, 3))
        np.testing.assert_allclose(atlas.texels[y0:y0 + h, x0:x0 + w, :3], expected)


def test_halved_keeps_single_texel_sides_and_drops_an_odd_last_row():
    image = np.arange(5 * 1 * 3, dtype=np.float32).reshape(5, 1, 3)
    out = albedo_atlas.halved(image)
    np.testing.assert_array_equal(out, 0.5 * (image[[0, 2]] + image[[1, 3]]))


def test_triangle_attributes_name_each_triangles_rect_and_leave_flat_ones_zero():
    # The rect's w is negative for Closest, its h for Extend; a flat triangle's rect is 0. The G-buffer's
    # albedo and the RSMs' bounce albedo of a textured triangle are its texels' factors; a flat one keeps
    # its own, and the probes' capture (which takes no texture) the per-triangle mean.
    from addon.engine.methods.direct import triangle_attributes
    from addon.engine.passes import gbuffer, probe_capture, rsm

    images = [np.ones((2, 4, 3), np.float32), np.ones((8, 8, 3), np.float32)]
    atlas = albedo_atlas.pack(images, width=16)
    uv = np.arange(4 * 3 * 2, dtype=np.float32).reshape(4, 3, 2)
    textures = AlbedoTextures(images=images, nearest=[True, False], clamp=[False, True],
                              index=np.array([1, -1, 0, 1]), uv=uv, scale=np.full((4, 3), 0.5, np.float32),
                              bounce_scale=np.full((4, 3), 0.25, np.float32))
    select = np.array([True, True, True, False])
    attrs = albedo_atlas.triangle_attributes(textures, atlas, select)
    rect = attrs["albedo_rect"][::3]
    np.testing.assert_array_equal(rect, [atlas.rects[1] * [1, 1, 1, -1], [0, 0, 0, 0], atlas.rects[0] * [1, 1, -1, 1]])
    np.testing.assert_array_equal(attrs["albedo_uv"].reshape(3, 3, 2)[[0, 2]], uv[[0, 2]])

    tris = np.array([[[0, 0, k], [1, 0, k], [0, 1, k]] for k in range(4)], np.float32)
    scene = Scene(tris, np.zeros_like(tris), np.full((4, 3), 0.7, np.float32), np.zeros((4, 3), np.float32),
                  bounce_albedo=np.full((4, 3), 0.9, np.float32), albedo_textures=textures)
    seen = triangle_attributes(scene, gbuffer.SPEC, select, np.zeros((4, 4), np.float32), atlas)
    np.testing.assert_allclose(seen["albedo"][::3], [[0.5] * 3, [0.7] * 3, [0.5] * 3])
    lit = triangle_attributes(scene, rsm.SPEC, select, np.zeros((4, 4), np.float32), atlas)
    np.testing.assert_allclose(lit["bounce_albedo"][::3], [[0.25] * 3, [0.9] * 3, [0.25] * 3])
    captured = triangle_attributes(scene, probe_capture.SPEC, select, np.zeros((4, 4), np.float32), atlas)
    np.testing.assert_allclose(captured["bounce_albedo"][::3], [[0.9] * 3] * 3)


def test_prepared_keeps_each_kept_triangles_texture():
    tris = np.array([[[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 0, 0], [0, 0, 0], [0, 0, 0]],
                     [[0, 0, 1], [1, 0, 1], [0, 1, 1]]], np.float32)  # the middle one has no area
    textures = AlbedoTextures(images=[np.ones((1, 1, 3), np.float32)], nearest=[True], clamp=[False],
                              index=np.array([0, -1, -1]), uv=np.zeros((3, 3, 2), np.float32),
                              scale=np.array([[1, 1, 1], [2, 2, 2], [3, 3, 3]], np.float32),
                              bounce_scale=np.array([[4, 4, 4], [5, 5, 5], [6, 6, 6]], np.float32))
    scene = Scene(tris, np.zeros_like(tris), np.zeros((3, 3), np.float32), np.zeros((3, 3), np.float32),
                  albedo_textures=textures)
    kept, _ = scene.prepared()
    np.testing.assert_array_equal(kept.albedo_textures.index, [0, -1])
    np.testing.assert_array_equal(kept.albedo_textures.scale[:, 0], [1, 3])
    np.testing.assert_array_equal(kept.albedo_textures.bounce_scale[:, 0], [4, 6])
