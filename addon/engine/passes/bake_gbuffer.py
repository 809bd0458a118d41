"""Texel G-buffer pass for bakes: the object's triangles rasterized in UV space instead of from a camera.

A bake is the ordinary light passes run on this G-buffer: the method's `gbuf` textures are filled here
(`run_gbuffer=False` then skips the camera G-buffer) and every texel is shaded as a camera pixel would be.

Inputs (mesh attributes, one vertex per triangle corner, the whole triangle repeated at each corner):
uv0..2 (the triangle's UVs, 0..1), p0..2 (world positions in the method's uploaded, re-centred frame, m),
n0..2 (world corner normals, unit, not flipped), albedo, corner (0, 1, 2). Uniforms: texel_size (w, h),
dilate (0: exact coverage, 1: grown by half a texel). Outputs (RGBA32F, bake size, GL row 0 = V = 0):
position (w = 1 where covered), normal, albedo (w = 1 where the texel's centre is covered,
CONSERVATIVE_COVERAGE where only its square is).

Coverage is conservative: every texel a triangle touches. A texel centre inside a triangle gets the exact
affine map of its UV; one outside takes the triangle's nearest point, with its distance (texels) as the
depth, so the depth test keeps the triangle that contains the centre, else the nearest one. The target
needs a depth texture (`target(size)` makes one over the method's G-buffer textures).

`points`: the same outputs for a list of samples at given texels (vertex-colour bakes).
`count`: texel centres covered per texel (SPEC drawn exactly, additively: albedo.w counts), to find
overlapping UVs.
"""

from __future__ import annotations

import numpy as np

from ..backends.base import Backend, ShaderSpec, Var
from .declare import GBUF_ALBEDO, GBUF_NORMAL, GBUF_POSITION, TRIANGLES, PassDecl

_TRI_ATTRS = (Var("uv0", "vec2"), Var("uv1", "vec2"), Var("uv2", "vec2"), Var("p0", "vec3"), Var("p1", "vec3"),
              Var("p2", "vec3"), Var("n0", "vec3"), Var("n1", "vec3"), Var("n2", "vec3"), Var("albedo", "vec3"),
              Var("corner", "float"))
_TRI_VARYINGS = (Var("v_bary", "vec3"), Var("v_bbox", "vec4"), Var("v_t0", "vec2"), Var("v_t1", "vec2"),
                 Var("v_t2", "vec2"), Var("v_p0", "vec3"), Var("v_p1", "vec3"),
                 Var("v_p2", "vec3"), Var("v_n0", "vec3"), Var("v_n1", "vec3"), Var("v_n2", "vec3"),
                 Var("v_albedo", "vec3"))
_UNIFORMS = (Var("texel_size", "vec2"), Var("dilate", "float"))
_OUTPUTS = (Var("out_position", "vec4"), Var("out_normal", "vec4"), Var("out_albedo", "vec4"))

# albedo.w of a texel the surface touches without covering its centre: still covered (> 0.5, as alpha
# is read everywhere), but told apart where a texel's sub-texels are averaged (lightmap.block_mean).
CONSERVATIVE_COVERAGE = 0.75

SPEC = ShaderSpec(name="bake_texel", vertex="bake/texel.vert.glsl", fragment="bake/texel.frag.glsl",
                  uniforms=_UNIFORMS, attributes=_TRI_ATTRS, varyings=_TRI_VARYINGS, outputs=_OUTPUTS,
                  defines=(("CONSERVATIVE_COVERAGE", repr(CONSERVATIVE_COVERAGE)),))
POINTS = ShaderSpec(name="bake_points", vertex="bake/points.vert.glsl", fragment="bake/points.frag.glsl",
                    uniforms=(Var("texel_size", "vec2"),),
                    attributes=(Var("texel", "vec2"), Var("pos_ws", "vec3"), Var("normal_ws", "vec3"),
                                Var("albedo", "vec3")),
                    varyings=(Var("v_pos_ws", "vec3"), Var("v_normal_ws", "vec3"), Var("v_albedo", "vec3")),
                    outputs=_OUTPUTS)


DECL = PassDecl("bake_gbuffer", "camera", (TRIANGLES,), (GBUF_POSITION, GBUF_NORMAL, GBUF_ALBEDO),
                "an object's triangles rasterized in UV space: lightmap texels as G-buffer pixels")


def triangle_attributes(uv: np.ndarray, positions: np.ndarray, normals: np.ndarray,
                        albedo: np.ndarray) -> dict[str, np.ndarray]:
    """Per-vertex arrays for SPEC/COUNT from (n, 3, 2) UVs, (n, 3, 3) positions and normals, (n, 3) albedo."""
    n = len(uv)
    rep = lambda a: np.repeat(np.asarray(a, np.float32), 3, axis=0)  # noqa: E731 - one vertex per corner
    attrs = {f"uv{k}": rep(uv[:, k]) for k in range(3)}
    attrs.update({f"p{k}": rep(positions[:, k]) for k in range(3)})
    attrs.update({f"n{k}": rep(normals[:, k]) for k in range(3)})
    attrs["albedo"] = rep(np.asarray(albedo, np.float32).reshape(n, 3))
    attrs["corner"] = np.tile(np.arange(3, dtype=np.float32), n).reshape(-1, 1)
    return attrs


def target(backend: Backend, gbuf: dict):
    """A render target over G-buffer textures {position, normal, albedo}, with its own depth texture."""
    size = gbuf["position"].size
    return backend.target([gbuf["position"], gbuf["normal"], gbuf["albedo"]], backend.depth_texture(size))


def run(backend: Backend, target, mesh, size: tuple[int, int]) -> None:
    """Clear `target` (position, normal, albedo of `size`, with depth) and draw `mesh` conservatively."""
    backend.clear(target, color=(0, 0, 0, 0), depth=1.0)
    if mesh is not None:
        backend.draw(backend.program(SPEC), target, mesh, depth_test=True,
                     uniforms={"texel_size": tuple(float(s) for s in size), "dilate": 1.0})


def count(backend: Backend, target, mesh, size: tuple[int, int]) -> None:
    """How many triangles contain each texel centre, in the third texture's alpha of `target` (three
    textures of `size`, no depth): exact coverage (a centre on a shared edge counts once, GL's fill
    rule), additive."""
    backend.clear(target, color=(0, 0, 0, 0))
    if mesh is not None:
        backend.draw(backend.program(SPEC), target, mesh, blend="add",
                     uniforms={"texel_size": tuple(float(s) for s in size), "dilate": 0.0})


def point_attributes(count_: int, size: tuple[int, int], positions: np.ndarray, normals: np.ndarray,
                     albedo: np.ndarray) -> dict[str, np.ndarray]:
    """Samples 0..count_-1 laid out row by row in a `size` texture (GL order: sample i at x = i % w,
    y = i // w)."""
    w = size[0]
    i = np.arange(count_)
    return {"texel": np.stack([i % w, i // w], axis=1).astype(np.float32),
            "pos_ws": np.asarray(positions, np.float32), "normal_ws": np.asarray(normals, np.float32),
            "albedo": np.asarray(albedo, np.float32)}


def run_points(backend: Backend, target, mesh, size: tuple[int, int]) -> None:
    backend.clear(target, color=(0, 0, 0, 0))
    if mesh is not None:
        backend.draw(backend.program(POINTS), target, mesh, uniforms={"texel_size": tuple(float(s) for s in size)})
