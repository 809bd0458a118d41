"""What L1 LPV reads on a concave surface a few cells across: a numpy model of Sibenik's barrel vault.

Most of Sibenik's LPV error lies on the nave's barrel vault, ~2.2 cells in radius at 32 cells, with
the point light near its axis (docs/LPV.md, "Sibenik: a vault two cells across"). This tool isolates
that geometry: the inner surface of a half cylinder (axis x, periodic along x, cell h = 1) of uniform
Lambertian exitance 1, injected as the method injects VPLs (cosine lobe at pos + 0.6 h n), propagated
with the improved transport on an empty grid (no geometry volume: Sibenik's vault read as low
without it), read with the lookup (trilinear at pos + 0.5 h n, clamped cosine about -n), against
the exact irradiance the vault receives from itself (2D kernel cos1 cos2 / (2 d) per unit arc).

    .venv/bin/python tools/lpv_barrel.py [--radii 2.2,4.4,8.8] [--classes none,axes,8]

--classes: `none` (one volume), `axes` (the method's six signed-axis emitter classes: a receiver
reads the total less its own class), or an integer K (K angular classes in the vault's plane, to
ask whether finer classes would help). --own-exact adds, with classes, the exact light of the
receiver's own class (what a gather over that class's VPLs would add). A research tool: slow
(numpy), not part of the method.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from addon.engine import lpv_reference as ref  # noqa: E402
from addon.engine.grid import Grid  # noqa: E402

GRID_YZ = 48  # cells across the vault's plane: room for the largest radius and its light's spread
GRID_X = 8  # periodic along the axis: an infinite vault
GRID = Grid(np.zeros(3), 1.0, (GRID_X, GRID_YZ, GRID_YZ))  # cell units: h = 1
ARC_SAMPLES = 2000


def arc(radius: float, centre: np.ndarray) -> tuple[np.ndarray, np.ndarray, float]:
    """Points (n, 2) and inward normals (n, 2) in (y, z) of the upper half circle; arc length per sample."""
    angles = (np.arange(ARC_SAMPLES) + 0.5) / ARC_SAMPLES * np.pi
    outward = np.stack([np.cos(angles), np.sin(angles)], axis=1)
    return centre + radius * outward, -outward, np.pi * radius / ARC_SAMPLES


def class_of(normal_yz: np.ndarray, classes: str) -> int:
    """Emitter class of an inward normal in the vault's plane (0 for `none`)."""
    if classes == "none":
        return 0
    if classes == "axes":  # dominant signed axis, as gpu_shaders/lpv/emitter_class.glsl (x is 0 here)
        axis = int(np.argmax(np.abs(normal_yz)))
        return 2 * axis + (0 if normal_yz[axis] > 0 else 1)
    k = int(classes)
    angle = (np.arctan2(normal_yz[1], normal_yz[0]) + np.pi / k) % (2.0 * np.pi)
    return int(angle // (2.0 * np.pi / k)) % k


def propagate(injected: np.ndarray) -> np.ndarray:
    """Accumulated coefficients (z, y, x, 4): the improved transport on the empty grid, periodic in x,
    long enough for the light to cross the grid's plane."""
    matrices, path = ref.gpu_improved_transfer()
    return ref.accumulate(injected, matrices, path, 3 * GRID_YZ, periodic_axes=(0,))


def in_3d(yz: np.ndarray) -> np.ndarray:
    """(n, 2) points or normals in the vault's plane -> (n, 3) with x = 0."""
    return np.c_[np.zeros(len(yz)), yz]


def inject(points: np.ndarray, normals: np.ndarray, ds: float) -> np.ndarray:
    """The snapshot (z, y, x, 4) of arc samples of exitance 1, injected as the method injects VPLs: a VPL
    of flux ds per sample and cell along the axis."""
    x_m = np.repeat(np.arange(GRID_X) + 0.5, len(points))  # the arc's copy through each cell centre
    pos = np.c_[x_m, np.tile(points, (GRID_X, 1))]
    return ref.inject(GRID, pos, np.tile(in_3d(normals), (GRID_X, 1)), np.full(len(pos), ds))


def exact_irradiance(
    point: np.ndarray, normal: np.ndarray, points: np.ndarray, normals: np.ndarray, ds: float
) -> float:
    """Irradiance at a vault point from the vault of exitance 1 (2D form-factor kernel, no occlusion:
    a concave arc sees all of itself)."""
    d = points - point
    dist = np.linalg.norm(d, axis=1)
    dist = np.where(dist > 1e-9, dist, np.inf)  # the receiver's own sample gives nothing
    cos_r = np.clip(d @ normal / dist, 0.0, None)
    cos_e = np.clip(-np.sum(d * normals, axis=1) / dist, 0.0, None)
    return float(np.sum(cos_r * cos_e / (2.0 * dist)) * ds)


def vault_readings(radius: float, classes: str, receiver_angles_deg: list[float], own_exact: bool = False) -> list:
    """[(angle from the springing in degrees, exact, LPV)] on the vault of `radius` cells. own_exact (with
    classes): add the exact irradiance from the receiver's own class, what a gather over that class's
    VPLs would add to the volume's reading of the other classes."""
    centre = np.array([GRID_YZ / 2 + 0.3, GRID_YZ / 2 + 0.1])  # off the cell lattice: no alignment luck
    points, normals, ds = arc(radius, centre)
    n_classes = 1 if classes == "none" else (6 if classes == "axes" else int(classes))
    of_class = np.array([class_of(n, classes) for n in normals])
    injected = [inject(points[of_class == c], normals[of_class == c], ds) for c in range(n_classes)]
    volumes = [propagate(v) if v.any() else v for v in injected]
    total = sum(volumes)
    rows = []
    for angle in receiver_angles_deg:
        k = int(round(np.radians(angle) / np.pi * ARC_SAMPLES - 0.5))
        point, normal = points[k], normals[k]
        # A receiver reads every class but its own (the reading is linear before its clamp).
        seen = total if classes == "none" else total - volumes[of_class[k]]
        receiver = np.array([[GRID_X / 2, *point]])
        lpv = np.pi * float(ref.lookup(seen, GRID, receiver, in_3d(normal[None]))[0])  # E (h = 1), not E / pi
        if own_exact and classes != "none":
            own = of_class == of_class[k]
            lpv += exact_irradiance(point, normal, points[own], normals[own], ds)
        rows.append((angle, exact_irradiance(point, normal, points, normals, ds), lpv))
    return rows


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--radii", default="2.2,4.4,8.8", help="vault radii in cells")
    ap.add_argument("--classes", default="none,axes", help="comma list of none, axes, or an integer K")
    ap.add_argument("--own-exact", action="store_true", help="with classes: add the own class's exact light")
    args = ap.parse_args(argv)
    angles = [90.0, 60.0, 36.0, 18.0]
    print("| classes | radius (cells) | " + " | ".join(f"{a:.0f} deg: LPV / exact" for a in angles) + " |")
    print("| --- | --- |" + " --- |" * len(angles))
    for classes in args.classes.split(","):
        for radius in (float(r) for r in args.radii.split(",")):
            rows = vault_readings(radius, classes, angles, args.own_exact)
            cells = " | ".join(f"{lpv / exact:.2f}" for _, exact, lpv in rows)
            print(f"| {classes} | {radius:g} | {cells} |", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
