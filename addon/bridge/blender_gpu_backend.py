"""BlenderGPUBackend: the engine's backend on Blender's `gpu` module (OpenGL, Vulkan, Metal).

Resources are declared through GPUShaderCreateInfo from the same ShaderSpec the moderngl backend turns
into GLSL text; the bodies in gpu_shaders/ are shared. Uniforms become push constants (ShaderSpec caps
them at 128 bytes for Vulkan). 3D textures are read back through a 2D atlas (see atlas_copy.comp.glsl).
"""

from __future__ import annotations

import contextlib
import os
import tempfile
from dataclasses import dataclass
from typing import Any

import gpu
import numpy as np
from gpu_extras.batch import batch_for_shader

from ..engine.backends.base import (
    FORMATS,
    Backend,
    Image,
    Mesh,
    Program,
    Sampler,
    ShaderSpec,
    Target,
    Texture,
    group_count,
)
from ..engine.errors import ShaderCompileError
from ..engine.shader_source import load, load_stages
from . import compat
from .gpu_init import ensure_gpu

_ACCESS = {"read": {"READ"}, "write": {"WRITE"}, "read_write": {"READ", "WRITE"}}

ATLAS_COPY = ShaderSpec(
    name="atlas_copy",
    compute="common/atlas_copy.comp.glsl",
    local_size=(8, 8, 1),
    samplers=(Sampler("volume", "3D"),),
    images=(Image("atlas", "2D", "RGBA32F", "write"),),
)


@dataclass
class _Mesh(Mesh):
    primitive: str
    count: int
    batch: Any


@dataclass
class _Target(Target):
    fbo: Any
    size: tuple[int, int]
    # A GPUFrameBuffer does not keep its attachments alive: without these references a depth texture
    # made just for the target is freed and the depth test silently stops working.
    attachments: tuple = ()


@contextlib.contextmanager
def _captured_output(result: list[str]):
    """Append to `result` what C code writes on file descriptors 1 and 2 meanwhile: Blender's logger
    prints the shader compiler's log there, and the Python exception carries none of it."""
    with tempfile.TemporaryFile(mode="w+") as log:
        saved = [os.dup(1), os.dup(2)]
        try:
            for fd in (1, 2):
                os.dup2(log.fileno(), fd)
            yield
        finally:
            for fd, old in zip((1, 2), saved, strict=True):
                os.dup2(old, fd)
                os.close(old)
            log.seek(0)
            result.append(log.read())


def _flat(arr: np.ndarray) -> np.ndarray:
    """Raw memory order of a gpu.types.Buffer (its memoryview has Fortran-order strides)."""
    return np.asarray(arr).ravel(order="F")


def _buffer(data: np.ndarray) -> gpu.types.Buffer:
    flat = np.ascontiguousarray(data, dtype=np.float32).ravel()
    return gpu.types.Buffer("FLOAT", flat.size, flat)


class BlenderGPUBackend(Backend):
    name = "blender"

    def __init__(self):
        ensure_gpu()
        self._programs: dict[ShaderSpec, Program] = {}
        self._live_uniforms: dict[ShaderSpec, set[str]] = {}  # per program, the uniforms it reads
        self._sync = None

    @property
    def renderer(self) -> str:
        p = gpu.platform
        return f"{p.backend_type_get()} {p.version_get()} / {p.renderer_get()} (Blender gpu)"

    # -- textures -----------------------------------------------------------------------------------
    def texture(self, size, fmt="RGBA32F", data=None) -> Texture:
        tex = Texture(tuple(size), fmt, None)
        if data is None:
            data = np.zeros(tuple(reversed(size)) + (FORMATS[fmt],), np.float32)
        self.write(tex, data)
        return tex

    def depth_texture(self, size) -> Texture:
        return Texture(tuple(size), "DEPTH32F", gpu.types.GPUTexture(tuple(size), format="DEPTH_COMPONENT32F"))

    def write(self, tex: Texture, data) -> None:
        # Blender 5.0's Python API cannot update a texture in place: a write replaces the GPU texture.
        expected = tuple(reversed(tex.size)) + (tex.channels,)
        arr = np.asarray(data, dtype=np.float32)
        if arr.size != int(np.prod(expected)):
            raise ValueError(f"write: data of shape {arr.shape} does not fit a texture of shape {expected}")
        tex.gl = gpu.types.GPUTexture(tex.size, format=tex.format, data=_buffer(arr))

    def read(self, tex: Texture) -> np.ndarray:
        shape = tuple(reversed(tex.size)) + (tex.channels,)
        if tex.is_3d:
            w, h, d = tex.size
            atlas = gpu.types.GPUTexture((w, h * d), format="RGBA32F")
            prog = self.program(ATLAS_COPY)
            self.dispatch(prog, group_count((w, h, d), ATLAS_COPY.local_size), samplers={"volume": tex},
                          images={"atlas": Texture((w, h * d), "RGBA32F", atlas)})
            raw = _flat(atlas.read()).reshape(d, h, w, 4)
            return np.ascontiguousarray(raw[..., : tex.channels], dtype=np.float32)
        return _flat(tex.gl.read()).astype(np.float32).reshape(shape)

    # -- programs -----------------------------------------------------------------------------------
    def program(self, spec: ShaderSpec) -> Program:
        cached = self._programs.get(spec)
        if cached is not None:
            return cached
        info = gpu.types.GPUShaderCreateInfo()
        for name, value in spec.defines:
            info.define(name, value)
        for u in spec.uniforms:
            info.push_constant(u.type.upper(), u.name)
        for slot, s in enumerate(spec.samplers):
            info.sampler(slot, f"FLOAT_{s.dim}", s.name)
        if spec.is_compute:
            sources = [load(spec.compute)]
            info.local_group_size(*spec.local_size)
            for slot, img in enumerate(spec.images):
                info.image(slot, img.format, f"FLOAT_{img.dim}", img.name, qualifiers=_ACCESS[img.access])
            info.compute_source(sources[0].text)
        else:
            sources = load_stages(spec.vertex, spec.fragment)
            for slot, a in enumerate(spec.attributes):
                info.vertex_in(slot, a.type.upper(), a.name)
            if spec.varyings:
                iface = gpu.types.GPUStageInterfaceInfo(f"{spec.name}_iface")
                for v in spec.varyings:
                    (iface.flat if v.flat else iface.smooth)(v.type.upper(), v.name)
                info.vertex_out(iface)
            for slot, o in enumerate(spec.outputs):
                info.fragment_out(slot, o.type.upper(), o.name)
            info.vertex_source(sources[0].text)
            info.fragment_source(sources[1].text)
        log: list[str] = []
        failed = None
        with _captured_output(log):
            try:
                shader = gpu.shader.create_from_info(info)
            except Exception as exc:
                failed = exc
        if failed is not None:
            mapped = sources[-1].map_error(log[0])
            raise ShaderCompileError(f"{spec.name}: {failed}\n{mapped.strip()}") from None
        prog = Program(spec, shader)
        self._programs[spec] = prog
        # The GLSL compiler drops a push constant its variant never reads (direct_light's POLYGONS
        # program has no use for a point's intensity), and setting a dropped one raises.
        live = set()
        for u in spec.uniforms:
            try:
                shader.uniform_from_name(u.name)
                live.add(u.name)
            except ValueError:
                pass
        self._live_uniforms[spec] = live
        return prog

    def _bind(self, prog: Program, uniforms, samplers) -> None:
        sh = prog.gl
        sh.bind()
        types = {u.name: u.type for u in prog.spec.uniforms}
        for name, value in (uniforms or {}).items():
            if name not in self._live_uniforms[prog.spec]:
                continue  # the compiler dropped it (program(), above)
            arr = np.asarray(value)
            if arr.shape == (4, 4):
                arr = arr.T  # numpy row-major maths -> GLSL column-major
            flat = arr.ravel().tolist() if arr.ndim else arr.item()
            if types[name].startswith("i") or types[name] == "int":
                sh.uniform_int(name, flat)
            else:
                sh.uniform_float(name, flat)
        for s in prog.spec.samplers:
            tex = (samplers or {})[s.name]
            sh.uniform_sampler(s.name, tex.gl)

    def dispatch(self, program, groups, uniforms=None, samplers=None, images=None) -> None:
        self._bind(program, uniforms, samplers)
        for img in program.spec.images:
            program.gl.image(img.name, (images or {})[img.name].gl)
        gpu.compute.dispatch(program.gl, *groups)

    # -- drawing ------------------------------------------------------------------------------------
    def mesh(self, program, attributes, primitive) -> _Mesh:
        data = {a.name: np.ascontiguousarray(attributes[a.name], dtype=np.float32) for a in program.spec.attributes}
        count = len(next(iter(data.values()))) if data else 0
        batch = batch_for_shader(program.gl, "POINTS" if primitive == "points" else "TRIS", data)
        return _Mesh(primitive, count, batch)

    def target(self, color, depth=None) -> _Target:
        slots, size = [], None
        for entry in color:
            tex, layer = entry if isinstance(entry, tuple) else (entry, None)
            size = tex.size[:2]
            slots.append(compat.layer_attachment(tex.gl, layer) if layer is not None else tex.gl)
        fbo = compat.framebuffer(tuple(slots), depth.gl if depth else None)
        attached = tuple(e[0] if isinstance(e, tuple) else e for e in color) + ((depth,) if depth else ())
        return _Target(fbo, tuple(size), tuple(t.gl for t in attached))

    def clear(self, target, color=(0, 0, 0, 0), depth=None) -> None:
        kwargs = {}
        if color is not None:
            kwargs["color"] = tuple(color)
        if depth is not None or color is not None:
            kwargs["depth"] = 1.0 if depth is None else depth
        with target.fbo.bind():
            target.fbo.clear(**kwargs)

    def draw(self, program, target, mesh, uniforms=None, samplers=None, blend="none", depth_test=False,
             viewport=None) -> None:
        with target.fbo.bind():
            gpu.state.viewport_set(*(viewport if viewport is not None else (0, 0, *target.size)))
            gpu.state.blend_set("ADDITIVE_PREMULT" if blend == "add" else "NONE")
            # LESS, as moderngl's default: where two surfaces tie in depth (a probe face's texel on a room's
            # corner) the first drawn wins on both backends, and the images agree.
            gpu.state.depth_test_set("LESS" if depth_test else "NONE")
            gpu.state.depth_mask_set(depth_test)
            gpu.state.point_size_set(1.0)
            self._bind(program, uniforms, samplers)
            mesh.batch.draw(program.gl)
            gpu.state.blend_set("NONE")
            gpu.state.depth_test_set("NONE")
            gpu.state.depth_mask_set(False)

    def finish(self) -> None:
        # No glFinish in the Python API: reading back a cleared 1x1 target waits for the queue before it.
        if self._sync is None:
            self._sync = gpu.types.GPUOffScreen(1, 1)
        with self._sync.bind():
            fb = gpu.state.active_framebuffer_get()
            fb.clear(color=(0, 0, 0, 0))
            fb.read_color(0, 0, 1, 1, 4, 0, "FLOAT")
