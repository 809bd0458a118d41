"""Zeroing textures with a compute pass (gpu_shaders/common/zero.comp.glsl) instead of a framebuffer
clear: a clear is a raster operation, and a compute GPU has few raster units (on an H100, clearing the
six VCT atlases at 128 cells took 0.9 ms on Sponza, 11 ms on Cornell; benchmarks/gpu/REPORT.md).

- images: 1 to 6 2D float textures of one size (the injection atlases).
- layers: layers [first, first + count) of 1 to 6 3D float textures of one size (the voxelizer's slabs).
"""

from __future__ import annotations

from ..backends.base import Backend, Image, ShaderSpec, Var, group_count

MAX_TEXTURES = 6


def _spec(count: int, volume: bool) -> ShaderSpec:
    return ShaderSpec(name=f"zero_{'layers' if volume else 'images'}_{count}", compute="common/zero.comp.glsl",
                      local_size=(4, 4, 4) if volume else (8, 8, 1),
                      images=tuple(Image(f"out{i}", "3D" if volume else "2D") for i in range(count)),
                      uniforms=(Var("first_layer", "int"), Var("layer_count", "int")) if volume else (),
                      defines=(("IMAGES", str(count)),) + ((("VOLUME", "1"),) if volume else ()))


SPECS = {(count, volume): _spec(count, volume) for count in range(1, MAX_TEXTURES + 1) for volume in (False, True)}


def images(backend: Backend, textures: list) -> None:
    """Set 2D textures (of one size) to 0."""
    spec = SPECS[(len(textures), False)]
    backend.dispatch(backend.program(spec), group_count(textures[0].size, spec.local_size),
                     images={f"out{i}": tex for i, tex in enumerate(textures)})


def layers(backend: Backend, volumes: list, first: int, count: int) -> None:
    """Set z-layers [first, first + count) of 3D textures (of one size) to 0."""
    spec = SPECS[(len(volumes), True)]
    w, h, _ = volumes[0].size
    backend.dispatch(backend.program(spec), group_count((w, h, count), spec.local_size),
                     uniforms={"first_layer": first, "layer_count": count},
                     images={f"out{i}": tex for i, tex in enumerate(volumes)})
