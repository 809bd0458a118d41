"""GLSL declarations generated from a ShaderSpec for backends that compile plain GLSL (moderngl).

Blender's backend declares the same resources through GPUShaderCreateInfo instead, so the bodies in
gpu_shaders/ never declare resources themselves.
"""

from __future__ import annotations

from .base import ShaderSpec

_ACCESS = {"read": "readonly ", "write": "writeonly ", "read_write": ""}


def defines(spec: ShaderSpec) -> list[str]:
    return [f"#define {k} {v}" for k, v in spec.defines]


def compute_header(spec: ShaderSpec) -> str:
    lx, ly, lz = spec.local_size
    lines = ["#version 430", *defines(spec), f"layout(local_size_x={lx}, local_size_y={ly}, local_size_z={lz}) in;"]
    lines += _uniforms(spec)
    for unit, img in enumerate(spec.images):
        lines.append(
            f"layout(binding={unit}, {img.format.lower()}) uniform {_ACCESS[img.access]}image{img.dim} {img.name};"
        )
    return "\n".join(lines) + "\n"


def vertex_header(spec: ShaderSpec) -> str:
    lines = ["#version 430", *defines(spec), *_uniforms(spec)]
    lines += [f"in {a.type} {a.name};" for a in spec.attributes]
    lines += [f"{'flat ' if v.flat else ''}out {v.type} {v.name};" for v in spec.varyings]
    return "\n".join(lines) + "\n"


def fragment_header(spec: ShaderSpec) -> str:
    lines = ["#version 430", *defines(spec), *_uniforms(spec)]
    lines += [f"{'flat ' if v.flat else ''}in {v.type} {v.name};" for v in spec.varyings]
    lines += [f"layout(location={i}) out {o.type} {o.name};" for i, o in enumerate(spec.outputs)]
    return "\n".join(lines) + "\n"


def _uniforms(spec: ShaderSpec) -> list[str]:
    lines = [f"uniform {u.type} {u.name};" for u in spec.uniforms]
    lines += [f"layout(binding={unit}) uniform sampler{s.dim} {s.name};" for unit, s in enumerate(spec.samplers)]
    return lines
