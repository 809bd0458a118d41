"""ModernGLBackend: a standalone OpenGL 4.3+ context (EGL headless; Mesa llvmpipe without a GPU).

Used by tests, CI, the CLI and bakes outside Blender. Never shares Blender's context: inside a windowed
Blender every call runs with this backend's own context entered.
"""

from __future__ import annotations

import ctypes
import ctypes.util
import functools
import gc
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..errors import BackendUnavailable, ShaderCompileError
from ..shader_source import load, load_stages
from . import glsl_header
from .base import FORMATS, Backend, Mesh, Program, ShaderSpec, Target, Texture

_DTYPE = {"RGBA32F": "f4", "RGBA16F": "f2", "R32F": "f4", "RG32F": "f4"}
_GL_FRAMEBUFFER = 0x8D40
_GL_COLOR_ATTACHMENT0 = 0x8CE0
_GL_DEPTH_BUFFER_BIT = 0x100


@dataclass
class _Mesh(Mesh):
    primitive: str
    count: int
    vao: Any
    buffers: list


@dataclass
class _Target(Target):
    fbo: Any
    size: tuple[int, int]
    layers: list  # (attachment index, 3D texture, layer) bound with glFramebufferTextureLayer


def _gl_library():
    """libGL entry points for the calls moderngl lacks: attaching a 3D-texture layer to an FBO, clearing
    depth alone."""
    # glvnd's libGL needs libGLX and so libX11, which a headless machine may lack; libOpenGL needs neither.
    for path in (ctypes.util.find_library("GL"), ctypes.util.find_library("OpenGL"), "libOpenGL.so.0"):
        if path:
            try:
                return ctypes.CDLL(path)
            except OSError:
                continue
    raise BackendUnavailable("libGL not found: cannot draw into 3D-texture layers")


class _EglCurrent:
    """Saves and restores the thread's current EGL context. glcontext's `with ctx:` releases the
    context on exit instead of restoring the previous one, which would leave Blender's gpu module
    (also on EGL in background mode) without its context."""

    _EGL_DRAW, _EGL_READ = 0x3059, 0x305A

    def __init__(self):
        path = ctypes.util.find_library("EGL")
        self._egl = ctypes.CDLL(path) if path else None
        if self._egl:
            for fn in ("eglGetCurrentDisplay", "eglGetCurrentContext", "eglGetCurrentSurface"):
                getattr(self._egl, fn).restype = ctypes.c_void_p
            self._egl.eglGetCurrentSurface.argtypes = [ctypes.c_int]
            self._egl.eglMakeCurrent.argtypes = [ctypes.c_void_p] * 4

    def save(self):
        if not self._egl:
            return None
        e = self._egl
        return (e.eglGetCurrentDisplay(), e.eglGetCurrentSurface(self._EGL_DRAW),
                e.eglGetCurrentSurface(self._EGL_READ), e.eglGetCurrentContext())

    def restore(self, saved) -> None:
        if saved and saved[3]:
            self._egl.eglMakeCurrent(*saved)


def _in_own_context(method):
    """Run a backend call with this backend's context current, restoring the caller's afterwards:
    in a process that also runs Blender's gpu module, whichever context is current gets the GL calls."""

    @functools.wraps(method)
    def wrapper(self, *args, **kwargs):
        saved = self._egl.save()
        if saved and saved[3] == self._own_context:
            return method(self, *args, **kwargs)
        # No cyclic garbage collection while our context is current: a collection here can free Blender
        # gpu objects (textures, framebuffers) whose release then deletes GL names in *this* context,
        # i.e. our objects of the same names (a test late in the suite lost its G-buffer that way).
        collecting = gc.isenabled()
        gc.disable()
        try:
            with self.ctx:
                return method(self, *args, **kwargs)
        finally:
            self._egl.restore(saved)
            if collecting:
                gc.enable()

    return wrapper


@dataclass
class _Program(Program):
    members: frozenset = frozenset()  # the names moderngl found (uniforms the compiler kept, ...)
    last_values: dict = field(default_factory=dict)  # plain uniform values last written (_set_uniforms)


def _plain(value) -> bool:
    """An int or float, or a tuple of them: written as is and compared cheaply."""
    if isinstance(value, (int, float)):
        return True
    return isinstance(value, tuple) and all(isinstance(v, (int, float)) for v in value)


class ModernGLBackend(Backend):
    name = "moderngl"

    def __init__(self, ctx=None):
        try:
            import moderngl
        except ImportError as exc:  # pragma: no cover - the venv always has it
            raise BackendUnavailable(f"moderngl is not installed: {exc}") from exc
        self._mgl = moderngl
        self._egl = _EglCurrent()
        # Creating a context makes it current and `with ctx:` below releases it: the caller's context
        # (Blender's gpu module in background mode) must be made current again at the end, or its next
        # call fails ("gpu.texture.new(...) failed" after a bake made a second backend).
        callers = self._egl.save()
        if ctx is None:
            try:
                ctx = moderngl.create_standalone_context(backend="egl", require=430)
            except Exception as exc:
                self._egl.restore(callers)
                raise BackendUnavailable(f"no EGL OpenGL 4.3 context: {exc}") from exc
        self.ctx = ctx
        # GL objects whose Python handles die are queued and released by _collect() inside our own
        # context: with moderngl's default (None) nothing is ever released, and every re-voxelization
        # or new scene leaked its buffers and textures; "auto" would release from __del__, possibly
        # while Blender's context is current, deleting its objects of the same names.
        ctx.gc_mode = "context_gc"
        with ctx:
            current = self._egl.save()
        self._own_context = current[3] if current else None
        self._programs: dict[ShaderSpec, Program] = {}
        self._gl = _gl_library()
        self._gl.glFramebufferTextureLayer.argtypes = [ctypes.c_uint] * 3 + [ctypes.c_int] * 2
        self._gl.glClearDepth.argtypes = [ctypes.c_double]
        self._gl.glClear.argtypes = [ctypes.c_uint]
        self._egl.restore(callers)

    @property
    def renderer(self) -> str:
        return self._renderer()

    @_in_own_context
    def _renderer(self) -> str:
        info = self.ctx.info
        return f"OpenGL {info['GL_VERSION']} / {info['GL_RENDERER']} (moderngl)"

    # -- textures -----------------------------------------------------------------------------------
    def _collect(self) -> None:
        """Release the GL objects dropped since the last allocation (call inside our context)."""
        self.ctx.gc()

    @_in_own_context
    def texture(self, size, fmt="RGBA32F", data=None) -> Texture:
        self._collect()
        comps = FORMATS[fmt]
        dtype = _DTYPE[fmt]
        if len(size) == 3:
            gl = self.ctx.texture3d(tuple(size), comps, dtype=dtype)
        else:
            gl = self.ctx.texture(tuple(size), comps, dtype=dtype)
        gl.filter = (self._mgl.LINEAR, self._mgl.LINEAR)
        gl.repeat_x = gl.repeat_y = False
        if len(size) == 3:
            gl.repeat_z = False
        tex = Texture(tuple(size), fmt, gl)
        if data is None:  # zeros, as bytes: no float32 array to convert (a 1080p RGBA32F image is 33 MB)
            gl.write(bytes(int(np.prod(size)) * comps * np.dtype(dtype).itemsize))
        else:
            self.write(tex, data)
        return tex

    @_in_own_context
    def depth_texture(self, size) -> Texture:
        gl = self.ctx.depth_texture(tuple(size))
        return Texture(tuple(size), "DEPTH32F", gl)

    @_in_own_context
    def write(self, tex: Texture, data) -> None:
        arr = np.ascontiguousarray(data, dtype=np.float32)
        expected = tuple(reversed(tex.size)) + (tex.channels,)
        if arr.size != int(np.prod(expected)):
            raise ValueError(f"write: data of shape {arr.shape} does not fit a texture of shape {expected}")
        tex.gl.write(arr.astype(_DTYPE[tex.format]).tobytes())

    @_in_own_context
    def read(self, tex: Texture) -> np.ndarray:
        self.ctx.memory_barrier()
        raw = np.frombuffer(tex.gl.read(), dtype=_DTYPE[tex.format])
        return raw.astype(np.float32).reshape(tuple(reversed(tex.size)) + (tex.channels,))

    # -- programs -----------------------------------------------------------------------------------
    @_in_own_context
    def program(self, spec: ShaderSpec) -> Program:
        cached = self._programs.get(spec)
        if cached is not None:
            return cached
        if spec.is_compute:
            src = load(spec.compute)
            text = glsl_header.compute_header(spec) + src.text
            try:
                gl = self.ctx.compute_shader(text)
            except Exception as exc:
                raise ShaderCompileError(f"{spec.name}: {src.map_error(str(exc))}") from None
        else:
            vs, fs = load_stages(spec.vertex, spec.fragment)
            try:
                gl = self.ctx.program(
                    vertex_shader=glsl_header.vertex_header(spec) + vs.text,
                    fragment_shader=glsl_header.fragment_header(spec) + fs.text,
                )
            except Exception as exc:
                raise ShaderCompileError(f"{spec.name}: {fs.map_error(str(exc))}") from None
        prog = _Program(spec, gl, frozenset(gl))
        self._programs[spec] = prog
        return prog

    def _set_uniforms(self, prog: _Program, uniforms: dict[str, Any] | None) -> None:
        last = prog.last_values
        for name, value in (uniforms or {}).items():
            if name not in prog.members:
                continue  # declared but optimised out by the compiler
            if _plain(value):  # the common case, without numpy's conversions
                if name in last and type(last[name]) is type(value) and last[name] == value:
                    continue  # a program keeps its uniforms: an LPV propagation sets the same 7 each step
                prog.gl[name].value = value
                last[name] = value
                continue
            last.pop(name, None)
            arr = np.asarray(value)
            if arr.shape == (4, 4):  # numpy row-major maths -> GLSL column-major
                prog.gl[name].write(np.ascontiguousarray(arr.T, dtype=np.float32).tobytes())
            elif arr.ndim == 0:
                prog.gl[name].value = arr.item()
            else:
                prog.gl[name].value = tuple(arr.tolist())

    def _bind_samplers(self, prog: Program, samplers: dict[str, Texture] | None) -> None:
        for unit, s in enumerate(prog.spec.samplers):
            (samplers or {})[s.name].gl.use(location=unit)

    @_in_own_context
    def dispatch(self, program, groups, uniforms=None, samplers=None, images=None) -> None:
        self._set_uniforms(program, uniforms)
        self._bind_samplers(program, samplers)
        for unit, img in enumerate(program.spec.images):
            tex = (images or {})[img.name]
            tex.gl.bind_to_image(unit, read=img.access != "write", write=img.access != "read")
        program.gl.run(*groups)
        self.ctx.memory_barrier()

    # -- drawing ------------------------------------------------------------------------------------
    @_in_own_context
    def mesh(self, program, attributes, primitive) -> _Mesh:
        self._collect()
        buffers, content, count = [], [], None
        for var in program.spec.attributes:
            arr = np.ascontiguousarray(attributes[var.name], dtype=np.float32)
            arr = arr.reshape(arr.shape[0], -1)
            count = arr.shape[0] if count is None else count
            if arr.shape[0] != count:
                raise ValueError(f"mesh: attribute {var.name} has {arr.shape[0]} vertices, expected {count}")
            buf = self.ctx.buffer(arr.tobytes())
            buffers.append(buf)
            content.append((buf, f"{arr.shape[1]}f", var.name))
        vao = self.ctx.vertex_array(program.gl, content)
        return _Mesh(primitive, int(count or 0), vao, buffers)

    @_in_own_context
    def target(self, color, depth=None) -> _Target:
        attachments, layers, size = [], [], None
        for i, entry in enumerate(color):
            tex, layer = entry if isinstance(entry, tuple) else (entry, None)
            size = tex.size[:2]
            if layer is None:
                attachments.append(tex.gl)
            else:  # placeholder of the right size, replaced below by the 3D layer
                attachments.append(self.ctx.texture(tuple(size), 4, dtype="f4"))
                layers.append((i, tex, layer))
        fbo = self.ctx.framebuffer(color_attachments=attachments, depth_attachment=depth.gl if depth else None)
        if layers:
            fbo.use()
            for i, tex, layer in layers:
                self._gl.glFramebufferTextureLayer(_GL_FRAMEBUFFER, _GL_COLOR_ATTACHMENT0 + i, tex.gl.glo, 0, layer)
        return _Target(fbo, tuple(size), layers)

    @_in_own_context
    def clear(self, target, color=(0, 0, 0, 0), depth=None) -> None:
        target.fbo.use()
        self.ctx.viewport = (0, 0, *target.size)
        if color is not None:
            target.fbo.clear(*color, depth=1.0 if depth is None else depth)
        elif depth is not None:  # depth alone: moderngl's clears always clear the colour attachments too
            self._gl.glClearDepth(depth)
            self._gl.glClear(_GL_DEPTH_BUFFER_BIT)

    @_in_own_context
    def draw(self, program, target, mesh, uniforms=None, samplers=None, blend="none", depth_test=False,
             viewport=None) -> None:
        mgl = self._mgl
        target.fbo.use()
        self.ctx.viewport = tuple(viewport) if viewport is not None else (0, 0, *target.size)
        flags = mgl.DEPTH_TEST if depth_test else mgl.NOTHING
        if blend == "add":
            flags |= mgl.BLEND
            self.ctx.blend_func = (mgl.ONE, mgl.ONE)
            self.ctx.blend_equation = mgl.FUNC_ADD
        self.ctx.enable_only(flags)
        self.ctx.point_size = 1.0
        self._set_uniforms(program, uniforms)
        self._bind_samplers(program, samplers)
        mesh.vao.render(mgl.POINTS if mesh.primitive == "points" else mgl.TRIANGLES)
        self.ctx.enable_only(mgl.NOTHING)

    @_in_own_context
    def finish(self) -> None:
        self.ctx.finish()

    @_in_own_context
    def gl_error(self) -> str:
        """The context's pending GL error ("GL_NO_ERROR" when none); tests check it around each test."""
        return self.ctx.error

