"""tools/diffusion_face_lookup.py's reading by face on cells whose answer is known."""

import importlib.util
import math
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
_spec = importlib.util.spec_from_file_location("diffusion_face_lookup", ROOT / "tools" / "diffusion_face_lookup.py")
face_lookup = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(face_lookup)

CELL_M = 0.5


def floor(flux_down_w: float, flux_up_w: float):
    """4^3 cells of 0.5 m, the layer z = 1 a floor (occupied, absorbing all of what crosses it along z and
    nothing along x, y), air above and below; per floor cell the flux absorbed from light travelling down
    (face 5, from the air above) and up (face 4, from below)."""
    block = np.zeros((4, 4, 4, 4))
    block[1] = (0.0, 0.0, 1.0, 1.0)
    faces = np.zeros((4, 4, 4, 6, 3))
    faces[1, :, :, 5] = flux_down_w
    faces[1, :, :, 4] = flux_up_w
    return block, faces


def read(block, faces, normal):
    point = np.array([[1.0, 1.0, 0.75]])  # on the floor's plane, between four of its cells
    return face_lookup.face_lookup(point, np.array([normal]), np.zeros(3), CELL_M, block, faces)[0]


def test_a_uniform_radiance_reads_as_itself_on_any_normal():
    # Radiance L: each face passes pi L h^2 one way, the floor absorbs all of it (block 1): E / pi = L,
    # up, down and tilted (the tilt's x part would see light through the floor's own cells, which send
    # none: only the z faces count, renormalised).
    radiance = 2.0
    block, faces = floor(math.pi * radiance * CELL_M**2, math.pi * radiance * CELL_M**2)
    for normal in ((0.0, 0.0, 1.0), (0.0, 0.0, -1.0), (0.6, 0.0, 0.8)):
        np.testing.assert_allclose(read(block, faces, np.array(normal)), radiance, rtol=1e-12)


def test_light_lands_on_the_side_it_travels_into():
    # 3 W absorbed from light travelling down: the floor's upper side reads 3 / (pi h^2), its lower 0.
    block, faces = floor(3.0, 0.0)
    np.testing.assert_allclose(read(block, faces, np.array([0.0, 0.0, 1.0])), 3.0 / (math.pi * CELL_M**2))
    assert np.all(read(block, faces, np.array([0.0, 0.0, -1.0])) == 0.0)


def test_no_cell_near_reads_zero():
    block, faces = floor(3.0, 3.0)
    block[...] = 0.0
    assert np.all(read(block, faces, np.array([0.0, 0.0, 1.0])) == 0.0)
