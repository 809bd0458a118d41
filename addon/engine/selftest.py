"""The backend self-test passes: the same small compute pass and additive point splat, run on any backend.

Used by the cross-backend tests (moderngl vs Blender gpu) and by `python -m addon doctor`.
"""

from __future__ import annotations

import numpy as np

from .backends.base import Backend, Image, Sampler, ShaderSpec, Var, group_count

SCALE_OFFSET = ShaderSpec(
    name="selftest_scale_offset",
    compute="selftest/scale_offset.comp.glsl",
    local_size=(4, 4, 4),
    samplers=(Sampler("src", "3D"),),
    images=(Image("dst", "3D", "RGBA32F", "write"),),
    uniforms=(Var("scale", "float"), Var("size_cells", "ivec3")),
)

SPLAT = ShaderSpec(
    name="selftest_splat",
    vertex="selftest/splat.vert.glsl",
    fragment="selftest/splat.frag.glsl",
    attributes=(Var("pos_ndc", "vec2"), Var("value", "vec4")),
    varyings=(Var("v_value", "vec4"),),
)


def run_scale_offset(backend: Backend, src: np.ndarray, scale: float) -> np.ndarray:
    """src (d, h, w, 4) -> src * scale + (x, y, z, pi) per texel, computed on the GPU."""
    d, h, w, _ = src.shape
    a = backend.texture((w, h, d), "RGBA32F", src)
    b = backend.texture((w, h, d), "RGBA32F")
    prog = backend.program(SCALE_OFFSET)
    backend.dispatch(prog, group_count((w, h, d), SCALE_OFFSET.local_size),
                     uniforms={"scale": scale, "size_cells": (w, h, d)}, samplers={"src": a}, images={"dst": b})
    return backend.read(b)


def run_splat(backend: Backend, size: tuple[int, int, int], voxels: np.ndarray, values: np.ndarray) -> np.ndarray:
    """Additively splat values (n, 4) at integer voxels (n, 3) into a zeroed volume; returns (d, h, w, 4)."""
    w, h, d = size
    vol = backend.texture(size, "RGBA32F")
    prog = backend.program(SPLAT)
    for z in range(d):
        sel = voxels[:, 2] == z
        if not np.any(sel):
            continue
        ndc = (voxels[sel, :2] + 0.5) / np.array([w, h]) * 2.0 - 1.0
        mesh = backend.mesh(prog, {"pos_ndc": ndc, "value": values[sel]}, "points")
        target = backend.target([(vol, z)])
        backend.draw(prog, target, mesh, blend="add")
    return backend.read(vol)

SH_EVAL = ShaderSpec(
    name="selftest_sh_eval",
    compute="selftest/sh_eval.comp.glsl",
    local_size=(8, 8, 1),
    samplers=(Sampler("dirs", "2D"), Sampler("coeffs", "2D")),
    images=(
        Image("basis_out", "2D", "RGBA32F", "write"),
        Image("lobe_out", "2D", "RGBA32F", "write"),
        Image("scalar_out", "2D", "RGBA32F", "write"),
    ),
)


def run_sh_eval(backend: Backend, dirs: np.ndarray, coeffs: np.ndarray) -> dict[str, np.ndarray]:
    """sh.glsl evaluated on the GPU for n directions (n, 3) and coefficient sets (n, 4)."""
    n = len(dirs)
    pad = np.zeros((n, 4), np.float32)
    pad[:, :3] = dirs
    tex_dirs = backend.texture((n, 1), "RGBA32F", pad.reshape(1, n, 4))
    tex_coeffs = backend.texture((n, 1), "RGBA32F", np.asarray(coeffs, np.float32).reshape(1, n, 4))
    outs = {name: backend.texture((n, 1), "RGBA32F") for name in ("basis_out", "lobe_out", "scalar_out")}
    prog = backend.program(SH_EVAL)
    backend.dispatch(prog, group_count((n, 1), SH_EVAL.local_size),
                     samplers={"dirs": tex_dirs, "coeffs": tex_coeffs}, images=outs)
    return {name: backend.read(tex).reshape(n, 4) for name, tex in outs.items()}


def _bvh_occluded_spec() -> ShaderSpec:
    from . import bvh
    from .passes import rsm

    return ShaderSpec(
        name="selftest_bvh_occluded",
        compute="selftest/bvh_occluded.comp.glsl",
        local_size=(8, 8, 1),
        samplers=(Sampler("origins", "2D"), Sampler("directions", "2D"), Sampler("bvh_nodes", "2D"),
                  Sampler("bvh_triangles", "2D")),
        images=(Image("hit_out", "2D", "RGBA32F", "write"),),
        uniforms=(Var("bvh_leaves", "int"),),
        defines=(("NODE_ROW", str(bvh.NODE_ROW)), ("OCCLUDER_ROW", str(rsm.OCCLUDER_ROW)),
                 ("LEAF_TRIANGLES", str(bvh.LEAF_TRIANGLES))),
    )


def run_bvh_occluded(backend: Backend, triangles_m: np.ndarray, origins: np.ndarray, directions: np.ndarray,
                     s_min: float) -> np.ndarray:
    """common/bvh.glsl's bvh_occluded on the GPU for n rays (origins, directions (n, 3)) against the
    triangles (t, 3, 3): (n,) booleans."""
    from .passes.sky_light import BvhTextures

    n = len(origins)
    tree = BvhTextures.upload(backend, triangles_m)
    packed = np.zeros((2, n, 4), np.float32)
    packed[0, :, :3], packed[0, :, 3], packed[1, :, :3] = origins, s_min, directions
    textures = [backend.texture((n, 1), "RGBA32F", packed[i].reshape(1, n, 4)) for i in range(2)]
    out = backend.texture((n, 1), "RGBA32F")
    spec = _bvh_occluded_spec()
    backend.dispatch(backend.program(spec), group_count((n, 1), spec.local_size),
                     samplers={"origins": textures[0], "directions": textures[1], "bvh_nodes": tree.nodes,
                               "bvh_triangles": tree.triangles},
                     images={"hit_out": out}, uniforms={"bvh_leaves": tree.leaves})
    return backend.read(out).reshape(n, 4)[:, 0] > 0.5
