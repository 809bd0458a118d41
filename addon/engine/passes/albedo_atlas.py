"""The Base Color textures the camera's G-buffer and the RSMs sample per pixel (Scene.albedo_textures),
packed into one texture: a raster pass binds one sampler however many images the scene has.

Inputs: Scene.albedo_textures (linear RGB images, row 0 = v 0; per triangle: image index, corner UVs,
scales). Output: an RGBA32F texture (ATLAS_WIDTH wide, as tall as the packing needs) and per triangle
the attributes `albedo_rect` (x0, y0, w, h in atlas texels, w negative for Closest and h for Extend;
w = 0: a flat albedo) and `albedo_uv`; a textured triangle's albedo attribute holds its scale.
gbuffer/gbuffer.frag.glsl and rsm/rsm.frag.glsl sample it (common/albedo_texture.glsl) as Cycles'
Image Texture node does at a ray's hit point: Closest reads
the texel the UV falls in, Linear interpolates the four around it (texel centres at (i + 0.5) / w),
Repeat wraps, Extend clamps. The filtering is done by hand with texelFetch, so texels of one image
never blend into another's (and there is no mip chain: Python-made textures have none, and Cycles'
camera rays at `filter_width` 0.01 px read the texture unfiltered too).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..backends.base import Backend, Texture
from ..scene import AlbedoTextures

# Atlas width in texels and its most height: at RGBA32F at most 256 MiB. Images that do not fit are
# halved (2 x 2 box means) until they do; the camera then reads a coarser texture, never a wrong one.
ATLAS_WIDTH = 4096


@dataclass
class Atlas:
    texels: np.ndarray  # (height, ATLAS_WIDTH, 4) float32, row 0 = v 0 of each image
    rects: np.ndarray   # (k, 4) float32: x0, y0, w, h of image k


def halved(image: np.ndarray) -> np.ndarray:
    """The image at half its size along each side longer than one texel (2 x 2 box means; an odd last
    row or column is dropped)."""
    h, w = image.shape[:2]
    if h > 1:
        image = 0.5 * (image[0:h - 1:2] + image[1:h:2])
    if w > 1:
        image = 0.5 * (image[:, 0:w - 1:2] + image[:, 1:w:2])
    return image


def shelf_pack(sizes: list[tuple[int, int]], width: int) -> tuple[np.ndarray, int] | None:
    """(k, 2) x0, y0 of each (h, w) size packed in rows ("shelves") of `width` texels, tallest first,
    and the height used; None when an image is wider than `width` or the height exceeds `width`."""
    origins = np.zeros((len(sizes), 2), np.int64)
    x = y = shelf = 0
    for k in sorted(range(len(sizes)), key=lambda i: -sizes[i][0]):
        h, w = sizes[k]
        if w > width:
            return None
        if x + w > width:
            x, y, shelf = 0, y + shelf, 0
        origins[k] = x, y
        x, shelf = x + w, max(shelf, h)
    height = y + shelf
    return (origins, height) if height <= width else None


def pack(images: list[np.ndarray], width: int = ATLAS_WIDTH) -> Atlas:
    """Every image in one atlas `width` texels wide, all halved together until they fit."""
    images = [np.asarray(i, np.float32) for i in images]
    while True:
        packed = shelf_pack([i.shape[:2] for i in images], width)
        if packed is not None:
            break
        images = [halved(i) for i in images]
    origins, height = packed
    texels = np.zeros((max(height, 1), width, 4), np.float32)
    for (x0, y0), image in zip(origins, images, strict=True):
        h, w = image.shape[:2]
        texels[y0:y0 + h, x0:x0 + w, :3] = image
    rects = np.array([[x0, y0, i.shape[1], i.shape[0]] for (x0, y0), i in zip(origins, images, strict=True)],
                     np.float32).reshape(-1, 4)
    return Atlas(texels, rects)


def upload(backend: Backend, atlas: Atlas | None) -> Texture:
    """The atlas as a texture; one black texel where the scene has no textures (the sampler is bound
    regardless, and no triangle reads it)."""
    texels = atlas.texels if atlas is not None else np.zeros((1, 1, 4), np.float32)
    return backend.texture((texels.shape[1], texels.shape[0]), data=texels)


def triangle_attributes(textures: AlbedoTextures | None, atlas: Atlas | None,
                        select: np.ndarray) -> dict[str, np.ndarray]:
    """Per-vertex arrays (three vertices per selected triangle) of `albedo_rect`, the image's (x0, y0,
    w, h) in the atlas with w negative for Closest and h negative for Extend (0: a flat albedo), and
    `albedo_uv`. A textured triangle's albedo attribute carries the factor its texels are multiplied by
    (methods/direct.triangle_attributes)."""
    count = int(select.sum())
    rect = np.zeros((count, 4), np.float32)
    uv = np.zeros((count, 3, 2), np.float32)
    if textures is not None and atlas is not None:
        index = textures.index[select]
        on = index >= 0
        signs = np.c_[np.where(textures.nearest, -1.0, 1.0), np.where(textures.clamp, -1.0, 1.0)]
        rect[on] = atlas.rects[index[on]] * np.c_[np.ones((len(signs), 2)), signs][index[on]]
        uv[on] = textures.uv[select][on]
    return {"albedo_rect": np.repeat(rect, 3, axis=0), "albedo_uv": uv.reshape(-1, 2)}
