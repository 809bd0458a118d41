"""cone_fields: the six cone fields' constants, emitters and step hold what the transport assumes (the
GPU's against these: tests/gpu/test_diffusion.py)."""

import numpy as np
import pytest

from addon.engine import cone_fields as cf
from addon.engine import diffusion_reference as ref


def test_a_step_moves_each_cones_light_whole_and_keeps_its_flux():
    # The p_f sum to 1 at every direction, so the moved matrices sum to the identity; the flux of what a
    # face carries is its raw flux (flux = sqrt(4 pi) gram[0] by Y_0's constancy). Both are identities of
    # the one quadrature, so they hold to rounding (1e-12).
    k = cf.constants()
    for b in cf.CONES:
        np.testing.assert_allclose(k["moved"][b].sum(0), np.eye(4), atol=1e-12)
        np.testing.assert_allclose(np.einsum("j,fjk->fk", k["flux"][b], k["moved"][b]), k["raw"][b], atol=1e-12)
        np.testing.assert_allclose(k["flux"][b], np.sqrt(4 * np.pi) * k["gram"][b][0], atol=1e-12)
    # The cones tile the sphere: their solid angles are 4 pi / 6 each, to the midpoint rule's 6e-5.
    solid_angles = np.sqrt(4 * np.pi) * k["flux"][:, 0]
    np.testing.assert_allclose(solid_angles, 4 * np.pi / 6, rtol=1e-4)


def test_emitters_carry_their_flux_in_the_cones_they_face():
    # Per side a Lambertian lobe: its six cone parts carry exactly its flux (each divided by the same
    # quadrature's whole lobe), none negative; a lobe about +z has nothing in the -z cone (max(0, w.z)
    # is 0 there) and shares the four side cones equally. An empty cell's light: the six iso parts carry
    # it exactly.
    rng = np.random.default_rng(0)
    normals = rng.normal(size=(20, 3))
    normals /= np.linalg.norm(normals, axis=1, keepdims=True)
    k = cf.constants()
    fluxes = np.array([cf.lobe_parts(normals, b) @ k["flux"][b] for b in cf.CONES])
    np.testing.assert_allclose(fluxes.sum(0), 1.0, atol=1e-12)
    assert fluxes.min() >= 0.0
    up = np.array([0.0, 0.0, 1.0])
    parts = [float(cf.lobe_parts(up, b) @ k["flux"][b]) for b in cf.CONES]
    assert parts[5] == 0.0
    np.testing.assert_allclose(parts[:4], parts[0], rtol=1e-12)
    np.testing.assert_allclose(sum(float(k["iso"][b] @ k["flux"][b]) for b in cf.CONES), 1.0, atol=1e-12)
    occupied = np.array([True, False])
    normal = np.array([[0.0, 0.0, 1.0], [0.0, 0.0, 0.0]])
    total = sum(cf.flux_w(cf.emit(np.array([2.0, 3.0]), np.array([1.0, 0.5]), normal, occupied, b, 0.5), b)
                for b in cf.CONES)
    assert total == pytest.approx(0.5 * (3.0 + 3.5), abs=1e-12)


def test_a_uniform_isotropic_field_is_unchanged_by_a_step():
    # Every cell of an empty grid holds each cone's part of 1 W of isotropic light; a cell away from the
    # grid's edges gathers from six neighbours like itself, whose faces' fields sum to their own: it is
    # unchanged (to rounding), in every cone.
    dims = (5, 5, 5)
    cell = ref.cells(np.zeros(dims, bool), np.zeros((*dims, 3)), np.zeros((*dims, 3)))
    for b in cf.CONES:
        field = np.broadcast_to(cf.constants()["iso"][b], (*dims, 4)).copy()
        nxt, absorbed = cf.step_by_face(field, cell, b)
        np.testing.assert_allclose(nxt[1:-1, 1:-1, 1:-1], field[1:-1, 1:-1, 1:-1], atol=1e-12)
        assert not absorbed.any()


def test_light_is_never_gained():
    # A closed box: random lobes on its walls' sides and isotropic light in its air. After each step the
    # light in flight plus all that was absorbed is at most the light emitted: the walls' outer sides
    # send theirs out of the box and off the grid, and light with no open face in its cone is dropped
    # (docs/DIFFUSION.md, "Light that has no way out"). With the air's light alone nothing can leave or
    # be dropped (its cells are all open), so there it is exactly the light emitted, to rounding.
    rng = np.random.default_rng(1)
    n = 8
    cell = ref.closed_box_cells(n)
    air = np.zeros((n, n, n), bool)
    air[2:-2, 2:-2, 2:-2] = True
    assert not (air & cell["occupied"]).any()
    walls = rng.uniform(0.0, 1.0, (2, n, n, n)) * cell["occupied"]
    lit_air = rng.uniform(0.0, 1.0, (n, n, n)) * air
    k = cf.constants()
    for fp, fm, exact in ((walls[0] + lit_air, walls[1], False), (lit_air, np.zeros_like(lit_air), True)):
        for b in cf.CONES:
            field = cf.emit(fp, fm, cell["normal"], cell["occupied"], b)
            emitted = cf.flux_w(field, b)
            absorbed = 0.0
            for _ in range(12):
                field, plus, minus = cf.step(field, cell, b)
                absorbed += plus.sum() + minus.sum()
                # Every face carries a field of its (non-negative) flux, so no cell's flux is negative.
                assert (field @ k["flux"][b]).min() >= -1e-12 * emitted
                kept = cf.flux_w(field, b) + absorbed
                assert kept <= emitted * (1 + 1e-12)
                if exact:
                    assert kept == pytest.approx(emitted, rel=1e-12)


@pytest.mark.parametrize("cone", cf.CONES)
def test_a_one_cell_wall_stops_light(cone):
    # test_diffusion_reference's wall (one cell thick across the grid at x = 4) and an isotropic emitter
    # at x = 1, in each cone field: after 40 steps not a bit of light is beyond the wall, and all the wall
    # absorbed is on its side facing the emitter.
    dims = (8, 8, 9)
    occ = np.zeros(dims, bool)
    occ[:, :, 4] = True
    normal = np.zeros((*dims, 3))
    normal[:, :, 4] = (1.0, 0.0, 0.0)
    proj = np.zeros((*dims, 3))
    proj[:, :, 4] = (1.0, 0.0, 0.0)
    cell = ref.cells(occ, normal, proj)
    light = np.zeros(dims)
    light[4, 4, 1] = 1.0
    field = cf.emit(light, np.zeros(dims), normal, occ, cone)
    plus_total = 0.0
    for _ in range(40):
        field, plus, _ = cf.step(field, cell, cone)
        plus_total += plus.sum()
    assert not field[:, :, 5:].any()
    assert plus_total == 0.0


@pytest.mark.slow  # 6 cones x 120 steps on 41^3 cells
@pytest.mark.xfail(strict=True, reason=(
    "measured: 4 pi r^2 E on the axis is 3.60 at 4 cells, 2.37 at 8 and 3.52 at 12: within its cone the "
    "light near the cone's axis keeps crossing the front face while the rest scatters sideways, so the "
    "axis keeps 2.4-3.6x its share (docs/DIFFUSION.md, 'Cone fields')"))
def test_a_point_sources_irradiance_falls_as_inverse_square():
    # test_diffusion_reference's point source (1 W isotropic in the centre of 41^3 empty cells, the flux
    # through the -x faces along +x over 120 steps), its light in the six cone fields: exact 1 / (4 pi)
    # x r^-2, within 10 % from 4 to 12 cells.
    size, c = 41, 20
    dims = (size, size, size)
    cell = ref.cells(np.zeros(dims, bool), np.zeros((*dims, 3)), np.zeros((*dims, 3)))
    through = np.zeros(size)
    for b in cf.CONES:
        field = np.zeros((*dims, 4))
        field[c, c, c] = cf.constants()["iso"][b]
        for _ in range(120):
            through += ref.inflow(cf.face_fluxes(field, cell["open"], b)[1])[c, c, :, 0]
            field, _ = cf.step_by_face(field, cell, b)
    r = np.arange(4, 13)
    np.testing.assert_allclose(4.0 * np.pi * r**2 * through[c + r], 1.0, rtol=0.10)
