"""The backend interface every pass is written against.

Resources are declared in Python (`ShaderSpec`, the Blender create-info style); bodies come from
gpu_shaders/. Only the portable subset of ARCHITECTURE.md section 3 is offered: compute dispatch with
sampler reads and image stores, draws of points/triangles into 2D textures or one layer of a 3D texture
(optionally with additive blending and a depth test), read-back to numpy. No atomics, no SSBOs.

Array layouts (numpy, C order): 2D textures (height, width, channels), row 0 = GL row 0 (bottom);
3D textures (depth, height, width, channels).
"""

from __future__ import annotations

import abc
import contextlib
import time
from dataclasses import dataclass, field, fields
from typing import Any

import numpy as np

from ..errors import ConfigError

FORMATS = {"RGBA32F": 4, "RGBA16F": 4, "R32F": 1, "RG32F": 2}
# (size, alignment) in bytes as Blender lays out push constants: every vec3 takes a whole 16-byte slot.
UNIFORM_LAYOUT = {
    "float": (4, 4), "int": (4, 4), "vec2": (8, 8), "vec3": (16, 16), "vec4": (16, 16),
    "ivec2": (8, 8), "ivec3": (16, 16), "ivec4": (16, 16), "mat4": (64, 16),
}
# Vulkan guarantees 128 bytes of push constants and Blender warns above that; desktop GPUs offer 256,
# which is the hard cap here. Passes above 128 bytes (rsm, direct_light) are listed in
# docs/ARCHITECTURE.md as a Vulkan portability risk to move into a uniform buffer.
PUSH_CONSTANT_LIMIT_BYTES = 256


@dataclass(frozen=True)
class Sampler:
    """A `sampler2D`/`sampler3D` read with texelFetch or texture() (linear filter, clamp to edge)."""

    name: str
    dim: str = "3D"


@dataclass(frozen=True)
class Image:
    """A float image for imageLoad/imageStore in a compute shader."""

    name: str
    dim: str = "3D"
    format: str = "RGBA32F"
    access: str = "write"  # "read", "write" or "read_write"


@dataclass(frozen=True)
class Var:
    """A uniform, vertex attribute, varying or fragment output: GLSL type and name; a varying's
    interpolation ("smooth", or "flat": the provoking vertex's value, unrounded; integers are always
    flat)."""

    name: str
    type: str
    interpolation: str = "smooth"

    @property
    def flat(self) -> bool:
        return self.interpolation == "flat" or self.type.startswith(("i", "u"))


def push_constant_bytes(uniforms: tuple[Var, ...]) -> int:
    """Bytes the uniforms take as push constants, in declaration order."""
    offset = 0
    for u in uniforms:
        size, align = UNIFORM_LAYOUT[u.type]
        offset = -(-offset // align) * align + size
    return offset


@dataclass(frozen=True)
class ShaderSpec:
    """A program: resources declared here, bodies read from gpu_shaders/ (paths relative to it).

    Either `compute`, or `vertex` + `fragment`. `defines` become `#define NAME VALUE` lines.
    """

    name: str
    compute: str | None = None
    vertex: str | None = None
    fragment: str | None = None
    local_size: tuple[int, int, int] = (8, 8, 1)
    samplers: tuple[Sampler, ...] = ()
    images: tuple[Image, ...] = ()
    uniforms: tuple[Var, ...] = ()
    attributes: tuple[Var, ...] = ()
    varyings: tuple[Var, ...] = ()
    outputs: tuple[Var, ...] = (Var("frag_color", "vec4"),)
    defines: tuple[tuple[str, str], ...] = field(default=())

    def __post_init__(self):
        if (self.compute is None) == (self.vertex is None or self.fragment is None):
            raise ConfigError(f"ShaderSpec {self.name}: give either compute or vertex + fragment")
        size = push_constant_bytes(self.uniforms)
        if size > PUSH_CONSTANT_LIMIT_BYTES:
            raise ConfigError(
                f"ShaderSpec {self.name}: {size} bytes of uniforms exceed the portable "
                f"{PUSH_CONSTANT_LIMIT_BYTES}-byte push-constant limit; pass data through a texture"
            )
        for img in self.images:
            if img.format not in FORMATS:
                raise ConfigError(
                    f"ShaderSpec {self.name}: image {img.name} format {img.format} not in {list(FORMATS)}")

    def __hash__(self) -> int:
        # Specs key the backends' program caches, looked up at every dispatch (an LPV update makes
        # hundreds): hash the nested field tuples once, not per lookup.
        cached = self.__dict__.get("_hash")
        if cached is None:
            cached = hash(tuple(getattr(self, f.name) for f in fields(self)))
            object.__setattr__(self, "_hash", cached)
        return cached

    @property
    def is_compute(self) -> bool:
        return self.compute is not None


@dataclass
class Texture:
    """A 2D or 3D float texture owned by a backend; `gl` is the backend's own handle."""

    size: tuple[int, ...]  # (w, h) or (w, h, d)
    format: str
    gl: Any

    @property
    def channels(self) -> int:
        return FORMATS[self.format]

    @property
    def is_3d(self) -> bool:
        return len(self.size) == 3


@dataclass
class Program:
    """A compiled ShaderSpec; `gl` is the backend's own handle."""

    spec: ShaderSpec
    gl: Any


class Mesh(abc.ABC):
    """Vertex data uploaded once: attribute name -> (n, k) float32; primitive 'points' or 'triangles'."""

    primitive: str
    count: int


class Target:
    """Render target: colour textures (a 2D texture or one layer of a 3D texture) and an optional depth.

    A marker type: each backend subclasses it with its own framebuffer handle."""


def group_count(size: tuple[int, ...], local: tuple[int, int, int]) -> tuple[int, int, int]:
    """Work groups covering `size` (x, y[, z]) with `local`-sized groups (shaders bound-check)."""
    s = tuple(size) + (1,) * (3 - len(size))
    return tuple(-(-s[i] // local[i]) for i in range(3))


class Backend(abc.ABC):
    """One GPU API. Passes call only these methods."""

    name: str

    @property
    @abc.abstractmethod
    def renderer(self) -> str: ...

    @abc.abstractmethod
    def texture(self, size: tuple[int, ...], fmt: str = "RGBA32F", data: np.ndarray | None = None) -> Texture: ...

    @abc.abstractmethod
    def write(self, tex: Texture, data: np.ndarray) -> None: ...

    @abc.abstractmethod
    def read(self, tex: Texture) -> np.ndarray:
        """(h, w, c) for 2D, (d, h, w, c) for 3D; float32."""

    @abc.abstractmethod
    def program(self, spec: ShaderSpec) -> Program:
        """Compile (cached by spec) or raise ShaderCompileError naming gpu_shaders/<file>:<line>."""

    @abc.abstractmethod
    def dispatch(
        self,
        program: Program,
        groups: tuple[int, int, int],
        uniforms: dict[str, Any] | None = None,
        samplers: dict[str, Texture] | None = None,
        images: dict[str, Texture] | None = None,
    ) -> None: ...

    @abc.abstractmethod
    def mesh(self, program: Program, attributes: dict[str, np.ndarray], primitive: str) -> Mesh: ...

    @abc.abstractmethod
    def target(self, color: list[Texture | tuple[Texture, int]], depth: Texture | None = None) -> Target:
        """A render target; a colour entry (tex3d, k) draws into layer k of a 3D texture."""

    @abc.abstractmethod
    def clear(self, target: Target, color: tuple[float, ...] | None = (0, 0, 0, 0), depth: float | None = None): ...

    @abc.abstractmethod
    def draw(
        self,
        program: Program,
        target: Target,
        mesh: Mesh,
        uniforms: dict[str, Any] | None = None,
        samplers: dict[str, Texture] | None = None,
        blend: str = "none",
        depth_test: bool = False,
        viewport: tuple[int, int, int, int] | None = None,
    ) -> None:
        """Rasterize `mesh`; blend 'add' accumulates (ONE, ONE) on all channels; points are 1 px.
        `viewport` (x, y, w, h): clip space maps onto that rectangle of the target (default: all of it),
        so a draw fills one tile of an atlas and nothing outside it."""

    @abc.abstractmethod
    def depth_texture(self, size: tuple[int, int]) -> Texture: ...

    @abc.abstractmethod
    def finish(self) -> None:
        """Block until all submitted GPU work is done (for timing)."""

    @contextlib.contextmanager
    def timed(self, timings_ms: dict[str, float], name: str):
        """Wall time of a block including GPU completion, added to timings_ms[name]."""
        self.finish()
        t0 = time.perf_counter()
        yield
        self.finish()
        timings_ms[name] = timings_ms.get(name, 0.0) + (time.perf_counter() - t0) * 1e3
