"""The `diffusion` transport's measured limits on its numpy twin (addon/engine/diffusion_reference.py):
the figures docs/DIFFUSION.md quotes, reproducible without a GPU.

For each transfer (cone, the paper's; directional):
1. A closed cube of N cells (one-cell walls, black: each bounce alone) whose floor has a lit patch of
   10 x 10 cells in its middle: the share of the patch's light absorbed after Y, 2Y, 4Y steps (Y = N),
   and where it lands: on the floor itself (exact 0: a plane cannot light itself) and on the ceiling
   (exact: the patch's view factor to the ceiling, about 0.23 at N = 32).
2. An isotropic point source in an empty grid: r^2 x the irradiance on the +x axis at 2..12 cells
   (exact: 1 / (4 pi) at every r).

Run: .venv/bin/python tools/diffusion_box.py [--cells 32]  (both transfers; about a minute at 32 cells)
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from addon.engine import diffusion_reference as ref  # noqa: E402
from addon.engine import sh  # noqa: E402


def ceiling_view_factor(n: int, samples: int = 1_000_000) -> float:
    """The exact share of the lit patch's Lambertian light that reaches the ceiling of `closed_box_cells`
    (planes at the walls' cell centres: a cube of n - 3 cells; the patch 10 cells wide about n / 2),
    by Monte Carlo over cosine-distributed directions (seeded; its standard error about 4e-4)."""
    rng = np.random.default_rng(0)
    side = n - 3.0
    x, y = (rng.uniform(n / 2 - 5 - 1.5, n / 2 + 5 - 1.5, samples) for _ in range(2))  # from the wall plane
    u, phi = rng.random(samples), 2 * np.pi * rng.random(samples)
    reach = side / np.sqrt(1 - u)  # the ray's length to the ceiling's plane, times sin(theta) below
    hx, hy = x + np.sqrt(u) * np.cos(phi) * reach, y + np.sqrt(u) * np.sin(phi) * reach
    return float(np.mean((hx > 0) & (hx < side) & (hy > 0) & (hy < side)))


def lambertian_face_shares(transfer: str, samples: int = 1_000_000) -> None:
    """Where one step sends an upward Lambertian lobe in an empty cell (every face open): the transfer's
    face fluxes of its L1 field against the exact shares of its directions w through each face,
    mean over the cosine lobe of max(0, w . d) / |w|_1 (Monte Carlo, seeded). The L1 field is broader
    than the lobe it stands for, so it sends more light sideways at every step than the light has."""
    rng = np.random.default_rng(0)
    u, phi = rng.random(samples), 2 * np.pi * rng.random(samples)
    w = np.stack([np.sqrt(u) * np.cos(phi), np.sqrt(u) * np.sin(phi), np.sqrt(1 - u)], axis=-1)
    exact = (np.maximum(w @ ref.DIRECTIONS.T, 0.0) / np.abs(w).sum(-1, keepdims=True)).mean(axis=0)
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


def point_source_figures(transfer: str, steps: int = 120, size: int = 41) -> None:
    through, _ = ref.point_source_axis_irradiance(steps, size, transfer)
    r = np.arange(2, 13)
    print(f"{transfer}: point source, {steps} steps on {size}^3 cells: 4 pi r^2 E(r) on the axis (exact 1)")
    print("  ".join(f"r={k}: {v:.2f}" for k, v in zip(r, 4 * np.pi * r**2 * through[r], strict=True)))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cells", type=int, default=32)
    args = parser.parse_args()
    for transfer in ref.TRANSFERS:
        lambertian_face_shares(transfer)
        box_figures(args.cells, transfer)
        point_source_figures(transfer)


if __name__ == "__main__":
    main()
