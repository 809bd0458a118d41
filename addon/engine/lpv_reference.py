"""numpy twin of the LPV transport: injection, propagation through the geometry volume, lookup.

The one numpy reference of the `lpv` method's transport: tests/gpu/test_lpv.py checks the GPU passes
against it (docs/LPV.md's SH-order and vault studies were built on it). It mirrors
- passes/lpv_inject.py (gpu_shaders/lpv/inject.vert.glsl): `inject`;
- passes/lpv_propagate.py (lpv/blocking.comp.glsl, lpv/propagate.comp.glsl, lpv/transfer.glsl):
  `transfer_matrices`, `path_weight`, `gpu_improved_transfer`, `blocking`, `pass_through`, `step`,
  `accumulate`;
- passes/lpv_lookup.py (lpv/lookup.comp.glsl): `lookup`.
It is written from the equations of docs/LPV.md, not from the shaders: `transfer_matrices` integrates
the improved transfer as a full matrix where the shader uses its symmetric form, so a test of one
against the other checks that form; `gpu_improved_transfer` builds that form from the pass's own
uniforms, for models that must follow the GPU over many steps. It computes in float64 what the GPU
computes in fp32.

Conventions (docs/LPV.md, "What a cell stores"; ARCHITECTURE.md section 4): a field is one colour
channel, an array (z, y, x, k) over the grid's cells of the SH coefficients, k = 4 (L1, order 1, y, z,
x) or 9 (L2, sh.py's order), of the radiant intensity in W/sr of the light leaving the cell, by
direction of travel; a cell's flux is 2 sqrt(pi) c0 in W. A direction d = sign * e_axis is (axis,
sign), axis 0 = x, listed in AXES (+x -x +y -y +z -z). Positions in metres (the Grid's frame), offsets
in cells, projected areas in cells^2.
"""

from __future__ import annotations

import functools

import numpy as np

from . import sh
from .grid import Grid
from .passes.lpv_propagate import improved_constants

AXES = ((0, 1.0), (0, -1.0), (1, 1.0), (1, -1.0), (2, 1.0), (2, -1.0))
DIRECTIONS = np.array([np.eye(3)[axis] * sign for axis, sign in AXES])  # unit vectors of AXES, (6, 3)
FLUX_PER_C0 = 2.0 * np.sqrt(np.pi)  # W per unit of c0: the integral of Y00 over the sphere
# CLPV's face solid angles seen from the neighbour's centre (the paper prints 0.4234413544, a typo).
FRONT_SOLID_ANGLE_SR = 0.4006696846
SIDE_SOLID_ANGLE_SR = 0.4234313544
INJECT_OFFSET_CELLS = 0.6  # a VPL goes to the cell in front of its surface (docs/LPV.md, "Injection")
LOOKUP_OFFSET_CELLS = 0.5  # a receiver reads the light half a cell in front of it
MIN_LOOKUP_WEIGHT = 1e-4  # lookup.comp.glsl: below this every corner is blocked (inside a solid)
_SLOT = (3, 1, 2)  # the coefficient index of axis x, y, z in (1, y, z, x)


def flux_w(field: np.ndarray) -> float:
    """The flux of a field (W): 2 sqrt(pi) c0 summed over its cells, exact for any coefficients."""
    return FLUX_PER_C0 * np.sum(field[..., 0], dtype=np.float64)


# -- transfer ------------------------------------------------------------------------------------------
@functools.cache
def transfer_matrices(variant: str, order: int = 1, n_theta: int = 1024) -> tuple[np.ndarray, ...]:
    """M_d (k x k) for the directions of AXES: cell A sends M_d c_A to its neighbour A + d.

    classic (L1 only): CLPV's five faces of the receiving cell, each the flux I_A(w_f) Omega_f re-emitted
    as a clamped-cosine lobe along the face's normal. improved: the projection of I_A(w) max(0, w.d) /
    |w|_1, integrated over n_theta x 2 n_theta directions (sh.sphere_quadrature)."""
    if variant == "classic":
        if order != 1:
            raise ValueError("the classic transfer is defined for L1 only")
        return tuple(_classic_matrix(d) for d in DIRECTIONS)
    return _improved_l1(n_theta) if order == 1 else _improved_per_axis(order, n_theta)


def _classic_matrix(d: np.ndarray) -> np.ndarray:
    m = np.zeros((4, 4))
    for f in DIRECTIONS:
        if f @ d < -0.5:
            continue  # the face the receiving cell shares with the sender
        front = f @ d > 0.5
        w = d if front else (d + 0.5 * f) / np.linalg.norm(d + 0.5 * f)  # sender's centre -> face centre
        omega_sr = FRONT_SOLID_ANGLE_SR if front else SIDE_SOLID_ANGLE_SR
        m += omega_sr * np.outer(sh.cosine_lobe_l1(f) / np.pi, sh.basis_l1(w))
    return m


def _improved_l1(n_theta: int) -> tuple[np.ndarray, ...]:
    # M_+x by quadrature (full 4x4), turned to the other axes exactly: a (theta, phi) rule is not
    # symmetric between x and z, so quadrature per axis would differ by its own ~1e-5 error.
    dirs, weights = sh.sphere_quadrature(n_theta, 2 * n_theta)
    basis = sh.basis_l1(dirs)
    wx = weights * np.maximum(dirs[:, 0], 0.0) / np.abs(dirs).sum(axis=1)
    m_x = np.einsum("k,ki,kj->ij", wx, basis, basis)
    mats = []
    for axis, sign in AXES:
        rot = np.eye(3)
        rot[:, [0, axis]] = rot[:, [axis, 0]]  # swap x and the axis: maps e_x to e_axis ...
        rot[:, 0] *= sign  # ... with d's sign (a signed permutation keeps |w|_1)
        p = np.zeros((4, 4))
        p[0, 0] = 1.0
        for i in range(3):
            for j in range(3):
                p[_SLOT[i], _SLOT[j]] = rot[i, j]
        mats.append(p @ m_x @ p.T)
    return tuple(mats)


def _improved_per_axis(order: int, n_theta: int) -> tuple[np.ndarray, ...]:
    # Band 2 does not map to itself under a signed permutation of the axes (3z^2 - 1 turns into a mix of
    # two functions), so L2 is integrated for each direction.
    dirs, weights = sh.sphere_quadrature(n_theta, 2 * n_theta)
    inv_l1 = 1.0 / np.abs(dirs).sum(axis=1)
    basis = _basis(order)(dirs)
    return tuple(np.einsum("k,ki,kj->ij", np.maximum(0.0, sign * dirs[:, axis]) * inv_l1 * weights, basis, basis)
                 for axis, sign in AXES)


@functools.cache
def path_weight(order: int = 1, n_theta: int = 1024) -> np.ndarray:
    """The matrix each propagated snapshot is accumulated with, integral Y_i Y_j / |w|_1 dw by quadrature:
    a visit of light travelling along w stands for a path of 1 / |w|_1 cells (docs/LPV.md, "path
    weight"). Its L1 block is the mean of 1 / |w|_1 over the sphere (0.674) times the identity, up to
    the quadrature's asymmetry; band 2 makes it a full matrix."""
    dirs, weights = sh.sphere_quadrature(n_theta, 2 * n_theta)
    inv_l1 = 1.0 / np.abs(dirs).sum(axis=1)
    basis = _basis(order)(dirs)
    return np.einsum("k,ki,kj->ij", inv_l1 * weights, basis, basis)


def gpu_improved_transfer() -> tuple[tuple[np.ndarray, ...], np.ndarray]:
    """(M_d for AXES, path-weight matrix) of the improved L1 transport as the GPU pass runs it: M_d in
    transfer.glsl's symmetric form from the uniforms lpv_propagate.improved_constants computes (M00 =
    1/6 exactly, Myy = Mzz), and its step weight times the identity. A propagation over many steps
    follows the GPU's to rounding; transfer_matrices' full quadrature differs by ~1e-6 per step."""
    c = improved_constants()
    mats = []
    for axis, sign in AXES:
        slot = _SLOT[axis]
        m = np.diag([1.0 / 6.0, c["m_side"], c["m_side"], c["m_side"]])
        m[slot, slot] = c["m_along"]
        m[0, slot] = m[slot, 0] = sign * c["m_cross"]
        mats.append(m)
    return tuple(mats), np.eye(4) * c["path_weight"]


def _basis(order: int):
    return sh.basis_l1 if order == 1 else sh.basis_l2


# -- geometry volume ---------------------------------------------------------------------------------
def blocking(vox_projected: np.ndarray, vox_offset: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """(block_plus, block_minus), each (z, y, x, 3): per axis b s(+) and b s(-), the shares of a cell's
    blocking b = min(1, projected area along the axis) on light leaving it along +axis and -axis.
    s(+-) = clamp(0.5 +- offset, 0, 1), offset the surfaces' mean offset from the centre (`vox_offset`,
    surface offsets), else 0.5: a surface blocks the half-cell transfer on its own side of the centre."""
    b = np.minimum(1.0, np.asarray(vox_projected, np.float64)[..., :3])
    if vox_offset is None:
        return 0.5 * b, 0.5 * b
    offset = np.asarray(vox_offset, np.float64)[..., :3]
    return b * np.clip(0.5 + offset, 0.0, 1.0), b * np.clip(0.5 - offset, 0.0, 1.0)


def pass_through(block_plus: np.ndarray, block_minus: np.ndarray) -> tuple[np.ndarray, ...]:
    """Per direction d of AXES, (z, y, x): the share of the light of A = B - d that enters B,
    max(0, 1 - b_A s_A(d) - b_B s_B(-d)) (light entering B along d meets B's share on leaving along -d;
    both cells may block fully, hence the clamp)."""
    out = []
    for axis, sign in AXES:
        leaving, entering = (block_plus, block_minus) if sign > 0 else (block_minus, block_plus)
        out.append(np.maximum(0.0, 1.0 - shifted(leaving[..., axis], axis, sign) - entering[..., axis]))
    return tuple(out)


# -- propagation -------------------------------------------------------------------------------------
def shifted(field: np.ndarray, axis: int, sign: float, periodic: bool = False) -> np.ndarray:
    """out[B] = field[B - d] for d = sign * e_axis (field indexed z, y, x, ...): what each cell gets from
    its neighbour behind it. Zero where B - d is outside the grid; wrapped round with `periodic` (a grid
    that stands for an infinite repetition along the axis)."""
    array_axis = 2 - axis
    if periodic:
        return np.roll(field, int(sign), axis=array_axis)
    out = np.zeros_like(field)
    src, dst = [slice(None)] * field.ndim, [slice(None)] * field.ndim
    src[array_axis], dst[array_axis] = (slice(0, -1), slice(1, None)) if sign > 0 else (slice(1, None), slice(0, -1))
    out[tuple(dst)] = field[tuple(src)]
    return out


def step(field: np.ndarray, matrices, through=None, periodic_axes: tuple[int, ...] = ()) -> np.ndarray:
    """The next snapshot (gather form): B receives sum_d through_d(B) M_d c(B - d). `through`:
    pass_through's shares, None in empty space; `periodic_axes`: axes (0 = x) that wrap round."""
    field = np.asarray(field, np.float64)
    out = np.zeros(field.shape)
    for i, ((axis, sign), m) in enumerate(zip(AXES, matrices, strict=True)):
        moved = shifted(field, axis, sign, axis in periodic_axes) @ m.T
        out += moved if through is None else through[i][..., None] * moved
    return out


def accumulate(injected: np.ndarray, matrices, path: np.ndarray, steps: int, through=None,
               periodic_axes: tuple[int, ...] = ()) -> np.ndarray:
    """The improved transport's accumulation: snapshots 1..steps, each weighted by `path`
    (path_weight). The injected snapshot is not accumulated: no light in the emitter's own cell."""
    acc, current = np.zeros(np.shape(injected)), injected
    for _ in range(steps):
        current = step(current, matrices, through, periodic_axes)
        acc += current @ path.T
    return acc


# -- injection and lookup ----------------------------------------------------------------------------
def injection_cells(grid: Grid, pos_m: np.ndarray, normals: np.ndarray) -> np.ndarray:
    """(n, 3) integer x, y, z: the cell holding pos + 0.6 h n of each VPL (it may lie outside the grid)."""
    h = grid.cell_size_m
    return np.floor((pos_m + INJECT_OFFSET_CELLS * h * normals - grid.origin_m) / h).astype(int)


def inject(grid: Grid, pos_m: np.ndarray, normals: np.ndarray, phi_w: np.ndarray, order: int = 1) -> np.ndarray:
    """The injected snapshot (z, y, x, k) of VPLs (pos_m, unit normals: (n, 3); flux phi_w: (n,) W): each a
    Lambertian emitter, I(w) = phi / pi max(0, n.w), projected (phi / pi x the clamped-cosine lobe) and
    added to its injection cell; a VPL whose cell lies outside the grid is dropped, as the GPU clips it."""
    cells = injection_cells(grid, pos_m, normals)
    inside = np.all((cells >= 0) & (cells < grid.dims), axis=1)
    lobe = sh.cosine_lobe_l1 if order == 1 else sh.cosine_lobe_l2
    lobes = lobe(normals[inside]) / np.pi
    field = np.zeros((*reversed(grid.dims), lobes.shape[-1]))
    x, y, z = cells[inside].T
    np.add.at(field, (z, y, x), np.asarray(phi_w)[inside, None] * lobes)
    return field


def lookup(acc: np.ndarray, grid: Grid, pos_m: np.ndarray, normals: np.ndarray, vox_normal: np.ndarray | None = None,
           offset_cells: float = LOOKUP_OFFSET_CELLS, band2_scale: float = 1.0) -> np.ndarray:
    """E / pi (n,) at receivers (pos_m, normals: (n, 3)) from an accumulation `acc` (z, y, x, k), in the
    units of Cycles' Diffuse Indirect: E = max(0, c(p) . cosine_lobe(-n)) / h^2, c trilinear (clamped to
    the edge cells) at p = pos + offset_cells h n. With `vox_normal` (z, y, x, 4: mean normal, area in
    cells^2) the geometry-aware lookup: the 8 corners weighted by their transmittance along n, 1 -
    min(1, area |n_cell . n|), and renormalised; plain trilinear where every corner blocks.
    band2_scale (L2): the factor on the lobe's band 2 (1: the clamped cosine)."""
    n = normals / np.maximum(np.linalg.norm(normals, axis=1, keepdims=True), 1e-12)
    k, h, dims = acc.shape[-1], grid.cell_size_m, np.array(grid.dims)
    g = (pos_m + offset_cells * h * n - grid.origin_m) / h - 0.5  # cell centres at integers
    i0 = np.floor(g).astype(int)
    f = g - i0
    lobe = sh.cosine_lobe_l1(-n) if k == 4 else sh.cosine_lobe_l2(-n) * np.r_[np.ones(4), np.full(5, band2_scale)]
    aware, plain, w_aware = np.zeros((len(n), k)), np.zeros((len(n), k)), np.zeros(len(n))
    for corner in np.ndindex(2, 2, 2):
        c = np.array(corner)
        idx = np.clip(i0 + c, 0, dims - 1)
        w = np.prod(np.where(c == 1, f, 1 - f), axis=1)
        v = acc[idx[:, 2], idx[:, 1], idx[:, 0]]
        plain += w[:, None] * v
        if vox_normal is not None:
            vn = vox_normal[idx[:, 2], idx[:, 1], idx[:, 0]]
            through = 1.0 - np.minimum(1.0, vn[:, 3] * np.abs(np.sum(vn[:, :3] * n, axis=1)))
            aware += (w * through)[:, None] * v
            w_aware += w * through
    s = plain
    if vox_normal is not None:
        open_ = (w_aware > MIN_LOOKUP_WEIGHT)[:, None]
        s = np.where(open_, aware / np.maximum(w_aware, MIN_LOOKUP_WEIGHT)[:, None], plain)
    return np.maximum(np.sum(s * lobe, axis=1), 0.0) / (h * h * np.pi)
