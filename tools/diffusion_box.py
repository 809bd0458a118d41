"""The `diffusion` transport's measured limits on its numpy twin (addon/engine/diffusion_reference.py):
the figures docs/DIFFUSION.md quotes, reproducible without a GPU.

For each transfer (cone, the paper's; directional):
1. A closed cube of N cells (one-cell walls, black: each bounce alone) whose floor has a lit patch of
   10 x 10 cells in its middle: the share of the patch's light absorbed after Y, 2Y, 4Y steps (Y = N),
   and where it lands: on the floor itself (exact 0: a plane cannot light itself) and on the ceiling
   (exact: the patch's view factor to the ceiling, about 0.23 at N = 32).
2. An isotropic point source in an empty grid: r^2 x the irradiance on the +x axis at 2..12 cells
   (exact: 1 / (4 pi) at every r).
3. (directional) The same cube with its whole floor lit, without and with a solid block standing on it
   (about a fifth of the floor's width, 0.6 of the height, black: each bounce alone): the share of the
   floor's light on the ceiling and on the block, and the block's by layer of cells, against Monte Carlo
   over the floor's cosine-distributed rays.

`--alternatives`: sharper angular models than L1 tried on the same twin, carried as `directional` is
(docs/DIFFUSION.md, "Small bright patches, and sharper angular models"): L2 with its exact face
matrices, a positive closure of the L1 field (M1-like), a flux limiter on L1, and L2 only at surfaces.
The ceiling's share from a 2 x 2 and a 10 x 10 lit patch, the point source at 4 and 8 cells, and figure
3's block (several minutes at 16 cells: the closure integrates per cell).

Run: .venv/bin/python tools/diffusion_box.py [--cells 32] [--alternatives]  (both transfers; about a
minute at 32 cells)
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from addon.engine import cone_fields, sh  # noqa: E402
from addon.engine import diffusion_reference as ref  # noqa: E402


def _cosine_directions(rng, count: int) -> np.ndarray:
    """`count` cosine-distributed directions about +z (a Lambertian surface's light), (count, 3)."""
    u, phi = rng.random(count), 2 * np.pi * rng.random(count)
    return np.stack([np.sqrt(u) * np.cos(phi), np.sqrt(u) * np.sin(phi), np.sqrt(1 - u)], axis=-1)


def ceiling_view_factor(n: int, half: int = 5, samples: int = 1_000_000) -> float:
    """The exact share of a lit floor patch's Lambertian light that reaches the ceiling of
    `closed_box_cells` (planes at the walls' cell centres: a cube of n - 3 cells; the patch 2 x half
    cells wide about n / 2), by Monte Carlo over cosine-distributed directions (seeded; its standard
    error about 4e-4 at a million samples)."""
    rng = np.random.default_rng(0)
    side = n - 3.0
    x, y = (rng.uniform(n / 2 - half - 1.5, n / 2 + half - 1.5, samples) for _ in range(2))  # from the wall plane
    d = _cosine_directions(rng, samples)
    reach = side / d[:, 2]  # the ray's length to the ceiling's plane
    hx, hy = x + d[:, 0] * reach, y + d[:, 1] * reach
    return float(np.mean((hx > 0) & (hx < side) & (hy > 0) & (hy < side)))


def block_in_box(n: int) -> tuple[int, int, int]:
    """The block of figure 3 in the closed box of n cells (ref.closed_box_cells' `block`): its sides over
    cells lo..hi, its top at cell `top`, scaled with the box (16 inner cells: 8..11 and 12)."""
    scale = (n - 3) / 16.0
    return int(2 + 6 * scale), int(2 + 9 * scale), int(2 + 10 * scale)


def floor_past_block(n: int, block, samples: int = 1_000_000, by_layer: bool = False):
    """Exact shares of a uniformly lit floor's Lambertian light (the floor outside the block's footprint;
    `block` as block_in_box's, or None) that reach the ceiling and that hit the block, with the planes at
    their cells' centres (the box's wall planes at 0 and n - 3), by Monte Carlo (seeded). `by_layer`:
    also the block's share per layer of cells, 2..top (the lowest from the floor's plane)."""
    rng = np.random.default_rng(0)
    side = n - 3.0
    x, y = rng.uniform(0, side, samples), rng.uniform(0, side, samples)
    if block is not None:
        lo, hi, top = (v - 1.0 for v in block)  # a cell's centre, from the wall plane
        outside = ~((x > lo) & (x < hi) & (y > lo) & (y < hi))
        x, y = x[outside], y[outside]
    origin = np.stack([x, y, np.zeros(len(x))], axis=-1)
    d = _cosine_directions(rng, len(origin))
    to_ceiling = side / d[:, 2]
    hit = origin + d * to_ceiling[:, None]
    on_ceiling = np.all((hit[:, :2] > 0) & (hit[:, :2] < side), axis=1)
    if block is None:
        return float(np.mean(on_ceiling)), 0.0
    with np.errstate(divide="ignore", invalid="ignore"):  # slab test against the block's box
        t1 = (np.array([lo, lo, 0.0]) - origin) / d
        t2 = (np.array([hi, hi, top]) - origin) / d
    enter = np.nanmax(np.minimum(t1, t2), axis=1)
    leave = np.nanmin(np.maximum(t1, t2), axis=1)
    on_block = (leave >= np.maximum(enter, 0.0)) & (enter < to_ceiling)
    shares = float(np.mean(on_ceiling & ~on_block)), float(np.mean(on_block))
    if not by_layer:
        return shares
    height = (origin[:, 2] + d[:, 2] * enter)[on_block]
    # Layer k's cells span k - 1.5 .. k - 0.5 from the floor's plane (cell 1's centre); the lowest starts at
    # the floor, the top layer's sides end at the top's plane (its cells' centres).
    edges = [0.0] + [k - 0.5 for k in range(2, block[2])] + [top + 1e-9]
    return shares, np.histogram(height, bins=edges)[0] / len(origin)


def _face_partition(w: np.ndarray) -> np.ndarray:
    """(K, 6): the share of direction w crossing each face, max(0, w.d) / |w|_1 (the partition M_d projects)."""
    return np.maximum(w @ ref.DIRECTIONS.T, 0.0) / np.abs(w).sum(-1, keepdims=True)


def lambertian_face_shares(transfer: str, samples: int = 1_000_000) -> None:
    """Where one step sends an upward Lambertian lobe in an empty cell (every face open): the transfer's
    face fluxes of its L1 field against the exact shares of its directions w through each face,
    mean over the cosine lobe of max(0, w . d) / |w|_1 (Monte Carlo, seeded). The L1 field is broader
    than the lobe it stands for, so it sends more light sideways at every step than the light has."""
    exact = _face_partition(_cosine_directions(np.random.default_rng(0), samples)).mean(axis=0)
    field = (sh.cosine_lobe_l1(np.array([0.0, 0.0, 1.0])) / np.pi).reshape(1, 1, 1, 4)
    ours = ref.face_fluxes(field, np.ones((1, 1, 1, 6)), transfer)[0, 0, 0] / ref.flux_w(field)
    print(f"{transfer}: an upward Lambertian lobe's shares through the faces +x -x +y -y +z -z")
    print("  exact " + " ".join(f"{v:.3f}" for v in exact) + "   L1 " + " ".join(f"{v:.3f}" for v in ours))


def box_figures(n: int, transfer: str) -> None:
    cell = ref.closed_box_cells(n)
    lit = np.zeros((n, n, n))
    mid = n // 2
    lit[1, mid - 5:mid + 5, mid - 5:mid + 5] = 1.0
    field = ref.emit(lit, np.zeros_like(lit), cell["normal"], cell["occupied"])
    total = ref.flux_w(field)
    absorbed = np.zeros_like(lit)
    print(f"{transfer}: closed box of {n} cells, 10 x 10 lit floor patch (exact: floor 0, ceiling "
          f"{ceiling_view_factor(n):.3f})")
    print("steps  absorbed  floor  ceiling  walls")
    done = 0
    for steps in (n, 2 * n, 4 * n):
        field, plus, minus = ref.propagate(field, cell, steps - done, transfer)
        done = steps
        absorbed += plus + minus
        floor = absorbed[1, 2:-2, 2:-2].sum() / total
        ceiling = absorbed[n - 2, 2:-2, 2:-2].sum() / total
        share = absorbed.sum() / total
        print(f"{steps:5d}  {share:8.3f}  {floor:5.3f}  {ceiling:7.3f}  {share - floor - ceiling:5.3f}")


def lit_field(lit: np.ndarray, normal: np.ndarray, coefficients: int) -> np.ndarray:
    """Lambertian emitters of flux `lit` (W per cell) about `normal`, in L1 (4) or L2 (9) coefficients."""
    lobes = sh.cosine_lobe_l1(normal) if coefficients == 4 else sh.cosine_lobe_l2(normal)
    return lit[..., None] * lobes / np.pi


def block_shares(n: int, block, transfer, coefficients: int = 4, by_layer: bool = False):
    """The shares of the lit floor's light (the floor outside the block's footprint) that the ceiling and
    the block absorb in the closed box of n cells with `block` (block_in_box's, or None) standing on it,
    after 2 n steps; `by_layer`: also the block's per layer of cells, 2..top."""
    cell = ref.closed_box_cells(n, block)
    lit = np.zeros((n, n, n))
    lit[1, 2:n - 2, 2:n - 2] = 1.0
    if block is not None:
        lo, hi, top = block
        lit[1, lo:hi + 1, lo:hi + 1] = 0.0
    field = lit_field(lit, cell["normal"], coefficients)
    total = ref.flux_w(field)
    _, plus, minus = ref.propagate(field, cell, 2 * n, for_cells(transfer, cell))
    absorbed = plus + minus
    on_block = 0.0 if block is None else absorbed[2:top + 1, lo:hi + 1, lo:hi + 1].sum() / total
    shares = float(absorbed[n - 2, 2:-2, 2:-2].sum() / total), float(on_block)
    if not by_layer:
        return shares
    return shares, absorbed[2:top + 1, lo:hi + 1, lo:hi + 1].sum(axis=(1, 2)) / total


def block_figures(n: int, transfer: str) -> None:
    block = block_in_box(n)
    lo, hi, top = block
    print(f"{transfer}: closed box of {n} cells, its floor lit, a block on it (cells {lo}..{hi}, top {top}): "
          "shares of the floor's light")
    print("         ceiling  exact  ratio  block  exact")
    for name, b in (("no block", None), ("block", block)):
        ceiling, on_block = block_shares(n, b, transfer)
        exact_ceiling, exact_block = floor_past_block(n, b)
        print(f"{name:8s} {ceiling:8.3f} {exact_ceiling:6.3f} {ceiling / exact_ceiling:6.3f} {on_block:6.3f} "
              f"{exact_block:6.3f}")
    ours = block_shares(n, block, transfer, by_layer=True)[1]
    exact = floor_past_block(n, block, by_layer=True)[1]
    print("the block's share by layer of cells, bottom to top:")
    print("  ours  " + " ".join(f"{v:.3f}" for v in ours))
    print("  exact " + " ".join(f"{v:.3f}" for v in exact))


def point_source_figures(transfer: str, steps: int = 120, size: int = 41) -> None:
    through, _ = ref.point_source_axis_irradiance(steps, size, transfer)
    r = np.arange(2, 13)
    print(f"{transfer}: point source, {steps} steps on {size}^3 cells: 4 pi r^2 E(r) on the axis (exact 1)")
    print("  ".join(f"r={k}: {v:.2f}" for k, v in zip(r, 4 * np.pi * r**2 * through[r], strict=True)))


# -- sharper angular models (--alternatives) -------------------------------------------------------------
def _sphere(count: int) -> np.ndarray:
    """`count` near-uniform unit directions (a Fibonacci spiral), each standing for 4 pi / count sr."""
    i = np.arange(count) + 0.5
    z = 1.0 - 2.0 * i / count
    phi = np.pi * (1.0 + 5.0**0.5) * i
    r = np.sqrt(1.0 - z * z)
    return np.stack([r * np.cos(phi), r * np.sin(phi), z], axis=-1)


def l2_transfer():
    """L2 (9 coefficients) with the exact face matrices M_d = <Y_i, Y_j max(0, w.d) / |w|_1> (no flux
    row factor: L2 holds a Lambertian lobe's partition to 0.002)."""
    dirs, weights = sh.sphere_quadrature(256, 512)
    basis = sh.basis_l2(dirs)
    m = np.einsum("k,ki,kj,kd->dij", weights, basis, basis, _face_partition(dirs))

    def transport(field: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        moved = np.einsum("dij,...j->...di", m, field)
        raw = ref.FLUX_PER_C0 * moved[..., 0]
        return raw, moved / np.where(raw > 0.0, raw, 1.0)[..., None]
    return transport


def closure_transfer(count: int = 2000, rho_max: float = 0.97):
    """A positive closure of the L1 field: per cell the lobe of a one-parameter family with the field's
    flux and mean direction (rho = |mean of w| in [0, 1)) is split by `_face_partition`, each face
    carrying its part's flux and first moment. The family: rho <= 1/3 the L1 function itself (positive
    there), up to 2/3 max(0, b + w.u), from 2/3 the cosine power max(0, w.u)^p, p = (2 rho - 1) / (1 -
    rho) (a Lambertian lobe at rho = 2/3, so its partition is exact). Every face flux is >= 0 and the
    faces carry the field's moments: no clamp, no flux row."""
    w = _sphere(count)
    part = _face_partition(w)
    b_grid = np.linspace(1e-4, 1.0, 4001)
    a = 1.0 / b_grid  # max(0, b + t) is max(0, 1 + a t) / a
    rho_grid = (0.5 * (1 - a**-2) + a / 3 + a**-2 / 3) / ((a + 1) ** 2 / (2 * a))  # from 2/3 down to 1/3

    def lobe(rho: np.ndarray, u: np.ndarray) -> np.ndarray:
        t = u @ w.T
        rho = rho[:, None]
        linear = 1.0 + 3.0 * np.minimum(rho, 1.0 / 3.0) * t
        b = np.interp(rho[:, 0], rho_grid[::-1], b_grid[::-1])[:, None]
        power = np.maximum((2.0 * rho - 1.0) / (1.0 - np.maximum(rho, 2.0 / 3.0)), 1.0)
        f = np.where(rho <= 1.0 / 3.0, linear,
                     np.where(rho < 2.0 / 3.0, np.maximum(0.0, b + t), np.maximum(t, 0.0) ** power))
        return f / f.sum(-1, keepdims=True)

    def transport(field: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        flat = field.reshape(-1, 4)
        flux = ref.FLUX_PER_C0 * flat[:, 0]
        mean = flat[:, [3, 1, 2]] / sh.Y1  # the intensity's first moment, x y z
        raw = np.zeros((len(flat), 6))
        moved = np.zeros((len(flat), 6, 4))
        lit = np.flatnonzero(flux > 1e-30)
        for start in range(0, len(lit), 1024):
            idx = lit[start:start + 1024]
            length = np.linalg.norm(mean[idx], axis=-1)
            u = np.where(length[:, None] > 0.0, mean[idx] / np.maximum(length, 1e-30)[:, None], (0.0, 0.0, 1.0))
            f = lobe(np.clip(length / flux[idx], 0.0, rho_max), u)
            share = f @ part
            moment = np.einsum("nk,kd,kc->ndc", f, part, w)
            raw[idx] = flux[idx, None] * share
            moved[idx, :, 0] = sh.Y00 * raw[idx]
            moved[idx, :, 1:] = sh.Y1 * flux[idx, None, None] * moment[..., [1, 2, 0]]
        raw, moved = raw.reshape(*field.shape[:-1], 6), moved.reshape(*field.shape[:-1], 6, 4)
        return raw, moved / np.where(raw > 0.0, raw, 1.0)[..., None]
    return transport


def limited_transfer(knee: float = 2.0 / 3.0):
    """`directional` with a flux limiter: each face's flux takes the isotropic part c0 / 6 times g, which
    falls from 1 at the knee (a Lambertian lobe's anisotropy rho = |c1| / (sqrt 3 c0) = 2/3, whose
    partition stays exact) to 0 for a collimated beam (rho = 1): a beam then crosses only the face it
    heads for. The flux row of M_d changes with it, so each face still carries its raw flux's M_d L."""
    m = ref.directional_matrices()

    def transport(field: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        c0 = field[..., 0]
        rho = np.linalg.norm(field[..., 1:], axis=-1) / (np.sqrt(3.0) * np.where(c0 > 0.0, c0, 1.0))
        g = np.clip((1.0 - rho) / (1.0 - knee), 0.0, 1.0)
        moved = np.einsum("dij,...j->...di", m, field)
        moved[..., 0] += ((g - 1.0) * c0 / 6.0)[..., None]
        raw = ref.FLUX_PER_C0 * moved[..., 0]
        return raw, moved / np.where(raw > 0.0, raw, 1.0)[..., None]
    return transport


def sharper_row_transfer(scale: float = 1.3):
    """`directional` with its flux row's weight on the face axis (diffusion_propagate.flux_cross) times
    `scale`: an upward Lambertian lobe then sends more than its exact share up (0.497 at 1.3) and less
    through each side, a test of whether the sideways share per step is what drains the block."""
    m = ref.directional_matrices()
    m[:, 0, 1:] *= scale

    def transport(field: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        moved = np.einsum("dij,...j->...di", m, field)
        raw = ref.FLUX_PER_C0 * moved[..., 0]
        return raw, moved / np.where(raw > 0.0, raw, 1.0)[..., None]
    return transport


class ByCells:
    """An angular model that depends on where the surfaces are: `make(cells)` gives the transfer for a
    scene's cells (ref.cells)."""

    def __init__(self, make):
        self.make = make


def for_cells(transfer, cell: dict):
    return transfer.make(cell) if isinstance(transfer, ByCells) else transfer


def surface_l2_transfer() -> ByCells:
    """L2 in the cells that hold a surface or border one, `directional` (L1, the flux row) in the air
    further off: the field carries nine coefficients, and the air's cells use and pass on the first four
    (the L2 band dropped there). Where light meets surfaces it has L2's angular detail; in open space
    L1's, which does not keep light to the axes."""
    l2 = l2_transfer()
    m1 = ref.directional_matrices()

    def make(cell: dict):
        near = cell["occupied"].copy()
        for axis in range(3):
            for shift in (1, -1):
                near |= np.roll(cell["occupied"], shift, axis=axis)

        def transport(field: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
            raw2, shape2 = l2(field)
            moved1 = np.einsum("dij,...j->...di", m1, field[..., :4])
            raw1 = ref.FLUX_PER_C0 * moved1[..., 0]
            shape1 = np.zeros(shape2.shape)
            shape1[..., :4] = moved1 / np.where(raw1 > 0.0, raw1, 1.0)[..., None]
            return (np.where(near[..., None], raw2, raw1),
                    np.where(near[..., None, None], shape2, shape1))
        return transport
    return ByCells(make)


def alternative_figures(n: int) -> None:
    models = (("directional", "directional", 4), ("L2", l2_transfer(), 9), ("closure", closure_transfer(), 4),
              ("limited", limited_transfer(), 4), ("L2 by surfaces", surface_l2_transfer(), 9),
              ("row x 1.3", sharper_row_transfer(1.3), 4))
    cell = ref.closed_box_cells(n)
    block = block_in_box(n)
    print(f"sharper angular models, closed box of {n} cells: per lit patch the share on the ceiling "
          "(exact: its view factor) and on the floor itself (exact 0); a point source's 4 pi r^2 E after 24 "
          "steps (exact 1 once all of its light has arrived); the whole floor lit with a block on it (figure "
          "3): the shares on the ceiling and on the block")
    print("model        up share  ceiling 2x2  floor 2x2  ceiling 10x10  floor 10x10  r=4   r=8   "
          "block: ceiling  block")
    exact = [ceiling_view_factor(n, half) for half in (1, 5)]
    exact_block = floor_past_block(n, block)
    print(f"exact           0.449  {exact[0]:11.3f}  {0:9.3f}  {exact[1]:13.3f}  {0:11.3f}  1.00  1.00  "
          f"{exact_block[0]:14.3f}  {exact_block[1]:5.3f}")
    up = np.array([0.0, 0.0, 1.0])
    for name, transfer, coefficients in models:
        lobe = sh.cosine_lobe_l1(up) if coefficients == 4 else sh.cosine_lobe_l2(up)
        single = (lobe / np.pi).reshape(1, 1, 1, -1)
        lone = ref.cells(np.ones((1, 1, 1), bool), np.array([[[[0.0, 0.0, 1.0]]]]), np.zeros((1, 1, 1, 3)))
        share = (ref.face_fluxes(single, np.ones((1, 1, 1, 6)), for_cells(transfer, lone))[0, 0, 0, 4]
                 / ref.flux_w(single))
        row = [f"{name:12s} {share:8.3f}"]
        for half, width in ((1, 11), (5, 13)):
            lit = np.zeros((n, n, n))
            lit[1, n // 2 - half:n // 2 + half, n // 2 - half:n // 2 + half] = 1.0
            field = lit_field(lit, cell["normal"], coefficients)
            total = ref.flux_w(field)
            _, plus, minus = ref.propagate(field, cell, 2 * n, for_cells(transfer, cell))
            absorbed = plus + minus
            row.append(f"{absorbed[n - 2, 2:-2, 2:-2].sum() / total:{width}.3f}  "
                       f"{absorbed[1, 2:-2, 2:-2].sum() / total:{width - 2}.3f}")
        size, centre = 21, 10
        empty = ref.cells(np.zeros((size,) * 3, bool), np.zeros((size,) * 3 + (3,)), np.zeros((size,) * 3 + (3,)))
        field = np.zeros((size,) * 3 + (coefficients,))
        field[centre, centre, centre, 0] = 1.0 / ref.FLUX_PER_C0
        through = np.zeros(size)
        in_empty = for_cells(transfer, empty)
        for _ in range(24):
            through += ref.inflow(ref.face_fluxes(field, empty["open"], in_empty))[centre, centre, :, 0]
            field, _, _ = ref.step(field, empty, in_empty)
        row.append("  ".join(f"{4 * np.pi * r**2 * through[centre + r]:.2f}" for r in (4, 8)))
        row.append("{:14.3f}  {:5.3f}".format(*block_shares(n, block, transfer, coefficients)))
        print("  ".join(row))
    print(cone_field_row(n))


def cone_field_row(n: int) -> str:
    """alternative_figures' measurements for the cone fields (cone_fields.py): every emitter's light split
    into the six face cones' fields, each propagated apart (the method's DiffusionConfig.cone_fields)."""
    k = cone_fields.constants()
    up = np.array([0.0, 0.0, 1.0])
    lone = np.ones((1, 1, 1, 6))
    share = sum(float(cone_fields.face_fluxes(cone_fields.lobe_parts(up, b).reshape(1, 1, 1, 4), lone, b)[1]
                      [0, 0, 0, 4]) for b in cone_fields.CONES)

    def absorbed_of(lit: np.ndarray, cell: dict) -> np.ndarray:
        total = np.zeros(lit.shape)
        for b in cone_fields.CONES:
            field = cone_fields.emit(lit, np.zeros_like(lit), cell["normal"], cell["occupied"], b)
            for _ in range(2 * n):
                field, plus, minus = cone_fields.step(field, cell, b)
                total += plus + minus
        return total

    row = [f"{'cone fields':12s} {share:8.3f}"]
    cell = ref.closed_box_cells(n)
    for half, width in ((1, 11), (5, 13)):
        lit = np.zeros((n, n, n))
        lit[1, n // 2 - half:n // 2 + half, n // 2 - half:n // 2 + half] = 1.0
        absorbed = absorbed_of(lit, cell)
        row.append(f"{absorbed[n - 2, 2:-2, 2:-2].sum() / lit.sum():{width}.3f}  "
                   f"{absorbed[1, 2:-2, 2:-2].sum() / lit.sum():{width - 2}.3f}")
    size, centre = 21, 10
    empty = ref.cells(np.zeros((size,) * 3, bool), np.zeros((size,) * 3 + (3,)), np.zeros((size,) * 3 + (3,)))
    through = np.zeros(size)
    for b in cone_fields.CONES:
        field = np.zeros((size,) * 3 + (4,))
        field[centre, centre, centre] = k["iso"][b]
        for _ in range(24):
            through += ref.inflow(cone_fields.face_fluxes(field, empty["open"], b)[1])[centre, centre, :, 0]
            field, _ = cone_fields.step_by_face(field, empty, b)
    row.append("  ".join(f"{4 * np.pi * r**2 * through[centre + r]:.2f}" for r in (4, 8)))
    lo, hi, top = block = block_in_box(n)
    cell = ref.closed_box_cells(n, block)
    lit = np.zeros((n, n, n))
    lit[1, 2:n - 2, 2:n - 2] = 1.0
    lit[1, lo:hi + 1, lo:hi + 1] = 0.0
    absorbed = absorbed_of(lit, cell)
    row.append(f"{absorbed[n - 2, 2:-2, 2:-2].sum() / lit.sum():14.3f}  "
               f"{absorbed[2:top + 1, lo:hi + 1, lo:hi + 1].sum() / lit.sum():5.3f}")
    return "  ".join(row)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cells", type=int, default=32)
    parser.add_argument("--alternatives", action="store_true",
                        help="only the sharper angular models (L2, a positive closure) beside directional")
    args = parser.parse_args()
    if args.alternatives:
        alternative_figures(args.cells)
        return
    for transfer in ref.TRANSFERS:
        lambertian_face_shares(transfer)
        box_figures(args.cells, transfer)
        point_source_figures(transfer)
    block_figures(args.cells, "directional")  # the cone transfer's light falls back onto the floor itself


if __name__ == "__main__":
    main()
