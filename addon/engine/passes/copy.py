"""Copying a 2D RGBA32F texture into another of its size (gpu_shaders/common/copy.comp.glsl), with a
compute pass for the reason zero.py gives: a blit is raster work, slow on compute GPUs."""

from __future__ import annotations

from ..backends.base import Backend, Image, Sampler, ShaderSpec, group_count

SPEC = ShaderSpec(name="copy_image", compute="common/copy.comp.glsl", local_size=(8, 8, 1),
                  samplers=(Sampler("source", "2D"),), images=(Image("target", "2D", "RGBA32F", "write"),))


def run(backend: Backend, source, target) -> None:
    """target := source (both 2D, of one size)."""
    backend.dispatch(backend.program(SPEC), group_count(target.size, SPEC.local_size), samplers={"source": source},
                     images={"target": target})
