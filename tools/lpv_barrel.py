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

from addon.engine import sh  # noqa: E402
from addon.engine.passes.lpv_propagate import improved_constants  # noqa: E402

GRID_YZ = 48  # cells across the vault's plane: room for the largest radius and its light's spread
GRID_X = 8  # periodic along the axis: an infinite vault
ARC_SAMPLES = 2000
INJECT_OFFSET = 0.6  # cells along n, as lpv_inject
LOOKUP_OFFSET = 0.5  # cells along n, as lpv_lookup


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


def transfer_matrices() -> list[tuple[int, int, np.ndarray]]:
    """(array axis, step sign, M_d) for the six directions of the improved transport."""
    c = improved_constants()
    out = []
    for array_axis, sh_index in ((1, 3), (2, 1), (3, 2)):  # volume axes x, y, z; SH order (1, y, z, x)
        for sign in (1, -1):
            m = np.diag([1.0 / 6.0, c["m_side"], c["m_side"], c["m_side"]])
            m[sh_index, sh_index] = c["m_along"]
            m[0, sh_index] = m[sh_index, 0] = sign * c["m_cross"]
            out.append((array_axis, sign, m))
    return out


def propagate(injected: np.ndarray, steps: int) -> np.ndarray:
    """Accumulated coefficients (4, X, Y, Z): the improved transport, S0 not accumulated, periodic in x."""
    path_weight = improved_constants()["path_weight"]
    transfers = transfer_matrices()
    current, accumulated = injected, np.zeros_like(injected)
    for _ in range(steps):
        moved = np.zeros_like(current)
        for array_axis, sign, m in transfers:
            shifted = np.roll(np.einsum("ij,j...->i...", m, current), sign, axis=array_axis)
            if array_axis != 1:  # y and z have borders: what rolled over leaves the grid
                border = [slice(None)] * 4
                border[array_axis] = 0 if sign > 0 else -1
                shifted[tuple(border)] = 0.0
            moved += shifted
        current = moved
        accumulated += path_weight * current
    return accumulated


def trilinear(volume: np.ndarray, point_xyz: np.ndarray) -> np.ndarray:
    """Coefficients (4,) at a point in cell units (cell centres at i + 0.5), periodic in x."""
    p = point_xyz - 0.5
    base = np.floor(p).astype(int)
    frac = p - base
    out = np.zeros(4)
    for corner in np.ndindex(2, 2, 2):
        w = np.prod([f if c else 1.0 - f for f, c in zip(frac, corner, strict=True)])
        i = base + np.array(corner)
        out += w * volume[:, i[0] % volume.shape[1], i[1], i[2]]
    return out


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
    injected = np.zeros((n_classes, 4, GRID_X, GRID_YZ, GRID_YZ))
    for point, normal in zip(points, normals, strict=True):
        cell = np.floor(point + INJECT_OFFSET * normal).astype(int)
        flux = ds * 1.0  # exitance 1 over ds x one cell along x
        lobe = flux / np.pi * sh.cosine_lobe_l1(np.array([0.0, normal[0], normal[1]]))
        injected[class_of(normal, classes), :, :, cell[0], cell[1]] += lobe[:, None]
    volumes = [propagate(v, 3 * GRID_YZ) if v.any() else np.zeros_like(v) for v in injected]
    total = sum(volumes)
    rows = []
    for angle in receiver_angles_deg:
        k = int(round(np.radians(angle) / np.pi * ARC_SAMPLES - 0.5))
        point, normal = points[k], normals[k]
        lookup = np.array([GRID_X / 2, *(point + LOOKUP_OFFSET * normal)])
        coeffs = trilinear(total, lookup)
        if classes != "none":
            coeffs = coeffs - trilinear(volumes[class_of(normal, classes)], lookup)
        # the light arriving at the surface travels along -n (grids store direction of travel)
        lpv = float(sh.irradiance(coeffs, -np.array([0.0, normal[0], normal[1]])))
        if own_exact and classes != "none":
            own = np.array([class_of(n, classes) == class_of(normal, classes) for n in normals])
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
