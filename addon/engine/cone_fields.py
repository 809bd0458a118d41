"""Cone fields (DiffusionConfig.cone_fields; docs/DIFFUSION.md "Cone fields"): the constants of the six
cone fields and their numpy twin (the GPU's are diffusion/propagate.comp.glsl and emit.comp.glsl with
CONES defined).

A single L1 field cannot tell light rising past a wall from light heading into it: at every step it
re-spreads what a face carried into a lobe as broad as a Lambertian one, and walls beside the light's
path take a share of it all the way up (docs/DIFFUSION.md, "Small bright patches"). Here the light
heading into each face cone (the directions w whose dominant signed axis is that face's, the cube face w
points through) is a field of its own, and light never leaves its cone in open space. Each cone's field
is four coefficients per colour of the L1 basis restricted to the cone: I(w) = sum_j c_j Y_j(w) for w in
cone b, 0 elsewhere. Six propagations per bounce (as the emitter classes have).

Constants per cone b (`constants`), from the cube-face midpoint quadrature (`face_quadrature`) over the
cone, which the cone's boundaries never cut:
- gram[b] = int_b Y_i Y_j dw, the basis' Gram matrix over the cone;
- flux[b][j] = int_b Y_j dw: a field's flux (W) is flux[b] . c (sqrt(4 pi) gram[b][0], Y_0 being
  constant, so the relations below hold to rounding whatever the quadrature);
- raw[b][f][j] = int_b Y_j p_f dw, p_f(w) = max(0, w . d_f)^e / sum_g max(0, w . d_g)^e (at e = 1
  the partition that LPV's improved transfer and `directional` project; PARTITION_EXPONENT below): the
  flux a field sends through face f;
- moved[b][f] = gram[b]^-1 int_b Y_i Y_j p_f dw: the field that flux arrives as, in the same cone. The
  p_f sum to 1, so the moved[b][f] sum to the identity (a uniform field is unchanged by a step), and
  flux[b] . moved[b][f] c = raw[b][f] . c (each face's field carries its flux);
- iso[b] = gram[b]^-1 int_b Y dw / (the quadrature's whole sphere, 4 pi to 6e-5): the cone's part of
  1 W of isotropic light, the six carrying exactly 1 W.

A step (`step_by_face`) is the directional one's, cone by cone: the raw face fluxes clamped at 0, kept on
open faces and scaled to the field's flux; a carrying face carries moved[b][f] c plus its share (by raw
flux) of the residual c - sum over the carrying faces of moved[b][f] c, so the faces carry c itself.
Emitters (`emit`): each side's Lambertian lobe about its normal, projected onto each cone's basis by
EMIT_QUADRATURE^2 points per cone face and scaled so the six cones carry its flux exactly.
"""

from __future__ import annotations

import functools

import numpy as np

from . import sh
from .diffusion_reference import (
    AXES,
    DIRECTIONS,
    EVERY_CLASS,
    emitter_class,
    gather,
    outflow,
    shared_residual,
    side_weights,
)

CONES = tuple(range(6))   # numbered as the faces: +x -x +y -y +z -z
QUADRATURE = 64           # midpoints per cube-face side for the constants
EMIT_QUADRATURE = 8       # ... for a lobe's projection (emit.comp.glsl uses the same)
# The face partition's exponent. At 1 each direction crosses the faces in proportion to its components,
# the mean displacement exact; but within a cone the light near the axis then keeps crossing the front
# face while the rest scatters sideways, and a small source's light stays on its cone's axis (a point
# source's on-axis irradiance 3.4-4.7x its share; a lamp's spot reappears sharp on the facing wall).
# Below 1 more of each tilted direction goes sideways and the light spreads. At 32 cells, 128 px, one
# bounce, rel_rmse_8 (cornell / window-room / thin-wall): 1: 0.220 / 0.584 / 0.262, 0.85: 0.209 / 0.512
# / 0.201, 0.75: 0.220 / 0.509 / 0.167, 0.65: 0.244 / 0.550 / 0.146, 0.5: 0.302 / 0.678 / 0.157
# (docs/DIFFUSION.md, "Cone fields").
PARTITION_EXPONENT = 0.8


def face_quadrature(cone: int, n: int) -> tuple[np.ndarray, np.ndarray]:
    """(directions (n^2, 3), solid angles (n^2,), sr): the midpoints of an n x n grid on the cube face of
    `cone` (the face at distance 1 along its axis), each standing for (2 / n)^2 / r^3 sr, r its distance
    from the centre (its texel's solid angle, to second order in 1 / n)."""
    axis, sign = AXES[cone]
    u, v = [a for a in range(3) if a != axis]
    t = (np.arange(n) + 0.5) * (2.0 / n) - 1.0
    s, r = np.meshgrid(t, t, indexing="ij")
    p = np.zeros((n * n, 3))
    p[:, axis] = sign
    p[:, u] = s.ravel()
    p[:, v] = r.ravel()
    length = np.linalg.norm(p, axis=1)
    return p / length[:, None], (2.0 / n) ** 2 / length**3


def _partition(w: np.ndarray) -> np.ndarray:
    """(K, 6): the share of direction w crossing each face, max(0, w . d)^PARTITION_EXPONENT normalised
    over the faces (at exponent 1 the directional transfer's max(0, w . d) / |w|_1)."""
    p = np.maximum(w @ DIRECTIONS.T, 0.0) ** PARTITION_EXPONENT
    return p / p.sum(-1, keepdims=True)


@functools.cache
def constants() -> dict[str, np.ndarray]:
    """gram (6, 4, 4), gram_inv (6, 4, 4), flux (6, 4), raw (6, 6, 4), moved (6, 6, 4, 4), iso (6, 4):
    per cone b (and face f) as the module docstring defines them."""
    gram, flux, raw, moved, iso = [], [], [], [], []
    sphere_sr = sum(face_quadrature(b, QUADRATURE)[1].sum() for b in CONES)
    for b in CONES:
        w, dw = face_quadrature(b, QUADRATURE)
        y = sh.basis_l1(w)
        g = np.einsum("k,ki,kj->ij", dw, y, y)
        g_inv = np.linalg.inv(g)
        p = _partition(w)
        gram.append(g)
        flux.append(np.einsum("k,kj->j", dw, y))
        raw.append(np.einsum("k,kf,kj->fj", dw, p, y))
        moved.append(np.einsum("il,k,kf,kl,kj->fij", g_inv, dw, p, y, y))
        iso.append(g_inv @ flux[-1] / sphere_sr)
    gram = np.array(gram)
    out = {"gram": gram, "gram_inv": np.linalg.inv(gram), "flux": np.array(flux), "raw": np.array(raw),
           "moved": np.array(moved), "iso": np.array(iso)}
    # The cone's symmetry makes many entries exactly 0 (a cone's light never crosses its back face; its
    # basis functions odd across a mirror plane of the cone do not couple), which the quadrature leaves at
    # rounding (1e-15): set them to 0, so the shader's compiler drops those products.
    return {k: np.where(np.abs(v) < 1e-12 * np.abs(v).max(), 0.0, v) for k, v in out.items()}


def lobe_parts(normals: np.ndarray, cone: int) -> np.ndarray:
    """(..., 4): cone `cone`'s field of a Lambertian lobe of 1 W about each unit normal (..., 3): the
    lobe projected onto the cone's basis by EMIT_QUADRATURE^2 points per cube face, divided by the same
    quadrature's flux of the whole lobe, so the six cones' fluxes sum to 1 W exactly."""
    n = np.asarray(normals, np.float64)
    total = np.zeros(n.shape[:-1])
    for b in CONES:
        w, dw = face_quadrature(b, EMIT_QUADRATURE)
        weights = np.maximum(n @ w.T, 0.0) * dw  # (..., K)
        total += weights.sum(-1)
        if b == cone:
            part = weights @ sh.basis_l1(w)
    return part @ constants()["gram_inv"][cone].T / np.where(total > 0.0, total, 1.0)[..., None]


def emit(flux_plus: np.ndarray, flux_minus: np.ndarray, normal: np.ndarray, occupied: np.ndarray, cone: int,
         albedo: np.ndarray | float = 1.0, emitter_class_only: int = EVERY_CLASS) -> np.ndarray:
    """Cone `cone`'s field (z, y, x, 4) of the emitters diffusion_reference.emit makes (each side's flux
    times albedo as a Lambertian lobe about its normal; an empty cell's isotropic; with an emitter class,
    only its sides, and an empty cell 1/5 of its light)."""
    fp = np.asarray(flux_plus, np.float64) * albedo
    fm = np.asarray(flux_minus, np.float64) * albedo
    share = 1.0
    normal = np.asarray(normal, np.float64)
    if emitter_class_only != EVERY_CLASS:
        fp = fp * (emitter_class(normal) == emitter_class_only)
        fm = fm * (emitter_class(-normal) == emitter_class_only)
        share = 0.2
    lobes = fp[..., None] * lobe_parts(normal, cone) + fm[..., None] * lobe_parts(-normal, cone)
    iso = (share * (np.asarray(flux_plus, np.float64) + np.asarray(flux_minus, np.float64)) * albedo)[..., None] \
        * constants()["iso"][cone]
    return np.where(np.asarray(occupied)[..., None], lobes, iso)


def flux_w(field: np.ndarray, cone: int) -> float:
    """The flux (W) of cone `cone`'s field (..., 4)."""
    return float(np.sum(field @ constants()["flux"][cone], dtype=np.float64))


def face_fluxes(field: np.ndarray, open_faces: np.ndarray, cone: int) -> tuple[np.ndarray, np.ndarray]:
    """(raw face fluxes, the flux leaving through each face), (z, y, x, 6) W, of cone `cone`'s field: the
    raw fluxes clamped at 0, kept on open faces and scaled to the field's flux."""
    k = constants()
    raw = field @ k["raw"][cone].T
    return raw, outflow(raw, open_faces, np.maximum(field @ k["flux"][cone], 0.0))


def step_by_face(field: np.ndarray, cell: dict, cone: int) -> tuple[np.ndarray, np.ndarray]:
    """One gather step of cone `cone`'s field (z, y, x, 4) through `cell` (diffusion_reference.cells):
    (the next field, the flux absorbed by the face it came through (z, y, x, 6), W)."""
    raw, out = face_fluxes(field, cell["open"], cone)
    moved = np.einsum("fij,...j->...fi", constants()["moved"][cone], field)  # (z, y, x, 6, 4)
    return gather(out, shared_residual(field, raw, moved, out), cell)


def step(field: np.ndarray, cell: dict, cone: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """One step (`step_by_face`): (next field, flux absorbed on the plus side, on the minus side), W."""
    nxt, absorbed = step_by_face(field, cell, cone)
    plus = side_weights(cell["normal"])
    return nxt, np.sum(absorbed * plus, -1), np.sum(absorbed * (1.0 - plus), -1)
