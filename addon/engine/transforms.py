"""4x4 view and projection matrices (numpy, row-major maths, OpenGL clip conventions: z in [-1, 1])."""

from __future__ import annotations

import numpy as np


def look_along(eye: np.ndarray, forward: np.ndarray, up_hint: np.ndarray | None = None) -> np.ndarray:
    """World -> view matrix of a camera at `eye` looking along `forward` (view space: -Z forward)."""
    f = np.asarray(forward, np.float64)
    f = f / np.linalg.norm(f)
    up = np.array([0.0, 0.0, 1.0]) if up_hint is None else np.asarray(up_hint, np.float64)
    if abs(np.dot(up, f)) > 0.99:  # up parallel to forward: any perpendicular works
        up = np.array([0.0, 1.0, 0.0]) if abs(f[1]) < 0.9 else np.array([1.0, 0.0, 0.0])
    right = np.cross(f, up)
    right /= np.linalg.norm(right)
    true_up = np.cross(right, f)
    view = np.eye(4)
    view[0, :3], view[1, :3], view[2, :3] = right, true_up, -f
    view[:3, 3] = -view[:3, :3] @ np.asarray(eye, np.float64)
    return view


def perspective(fov_rad: float, near: float, far: float) -> np.ndarray:
    """Square-aspect perspective projection with full field of view `fov_rad`."""
    f = 1.0 / np.tan(fov_rad / 2.0)
    p = np.zeros((4, 4))
    p[0, 0] = p[1, 1] = f
    p[2, 2] = (far + near) / (near - far)
    p[2, 3] = 2.0 * far * near / (near - far)
    p[3, 2] = -1.0
    return p


def orthographic(left: float, right: float, bottom: float, top: float, near: float, far: float) -> np.ndarray:
    p = np.eye(4)
    p[0, 0] = 2.0 / (right - left)
    p[1, 1] = 2.0 / (top - bottom)
    p[2, 2] = -2.0 / (far - near)
    p[0, 3] = -(right + left) / (right - left)
    p[1, 3] = -(top + bottom) / (top - bottom)
    p[2, 3] = -(far + near) / (far - near)
    return p


def box_corners(lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """The 8 corners (8, 3) of an axis-aligned box."""
    return np.array([[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])])
