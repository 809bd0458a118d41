"""The `diffusion` transport's numpy twin (addon/engine/diffusion_reference.py) against closed forms.

A field's flux is 2 sqrt(pi) c0 summed over its cells (W), linear in the coefficients, so what the
step conserves it conserves to float64 rounding: tolerances of 1e-12 relative say "exact". The GPU
passes are checked against this twin in tests/gpu/test_diffusion.py.
"""

import numpy as np
import pytest

from addon.engine import diffusion_reference as ref
from addon.engine import sh
from addon.engine.grid import Grid
from addon.engine.passes import diffusion_far_field

DIMS_ZYX = (6, 7, 8)


def empty_cells(dims=DIMS_ZYX):
    return ref.cells(np.zeros(dims, bool), np.zeros((*dims, 3)), np.zeros((*dims, 3)))


def test_the_face_cones_partition_the_sphere():
    # The six face cones of a cube seen from its centre cover the sphere once: their L1 projections sum
    # to that of 1, (2 sqrt(pi), 0, 0, 0), exactly (c0 = sqrt(pi) / 3 each, band 1 cancels in pairs).
    np.testing.assert_allclose(ref.CONES.sum(axis=0), [ref.FLUX_PER_C0, 0, 0, 0], rtol=0, atol=1e-14)
    # The cone's band-1 coefficient against a quadrature of the indicator (midpoint rule over a
    # discontinuous function: 2048 x 4096 directions resolve the cone's edge to ~1e-4).
    dirs, w = sh.sphere_quadrature(1024, 2048)
    inside = (dirs[:, 0] > np.abs(dirs[:, 1])) & (dirs[:, 0] > np.abs(dirs[:, 2]))
    np.testing.assert_allclose(sh.project(inside.astype(float), dirs, w), ref.CONES[0], rtol=0, atol=2e-4)


@pytest.mark.parametrize("transfer", ref.TRANSFERS)
def test_a_uniform_isotropic_field_is_unchanged_by_a_step(transfer):
    # The digest's check of the normalisation 3 / (2 pi): an isotropic intensity c0 sends <L, T_d> =
    # c0 sqrt(pi) / 3 through each face; each arrives as 3 / (2 pi) x that x T_d, and the six cones sum
    # to (2 sqrt(pi), 0, 0, 0): c0 exactly. directional: sum_d M_d = 1 (LPV's improved transfer).
    # Cells next to the grid's edge miss the inflow from outside, so only the interior is compared.
    field = np.zeros((*DIMS_ZYX, 4))
    field[..., 0] = 1.7
    nxt, plus, minus = ref.step(field, empty_cells(), transfer)
    # Band 1 cancels between opposite faces to 3e-17 (the cones' x, y, z terms in float64).
    np.testing.assert_allclose(nxt[1:-1, 1:-1, 1:-1], field[1:-1, 1:-1, 1:-1], rtol=1e-14, atol=1e-15)
    assert not plus.any() and not minus.any()  # no surface: nothing absorbed


def random_cells(rng, dims=DIMS_ZYX, share=0.3):
    occ = rng.random(dims) < share
    normal = rng.normal(size=(*dims, 3))
    normal /= np.linalg.norm(normal, axis=-1, keepdims=True)
    normal[rng.random(dims) < 0.2] = 0.0  # thin walls: the mean normal cancels
    proj = rng.random((*dims, 3)) * 1.5
    return ref.cells(occ, normal, proj)


@pytest.mark.parametrize("transfer", ref.TRANSFERS)
@pytest.mark.parametrize("seed", range(5))
def test_a_step_never_adds_light(seed, transfer):
    # Fields with strong band 1 (|c1| up to 3 c0: negative lobes the clamp must not turn into light):
    # the flux carried on plus the flux absorbed is at most the flux of the cells with positive c0 (the
    # rest may leave the grid, never exceed it); with no open boundary (light kept inside by a closed
    # shell of surfaces) it is equal, to rounding.
    rng = np.random.default_rng(seed)
    field = rng.normal(size=(*DIMS_ZYX, 4))
    field[..., 0] = np.abs(field[..., 0])
    cell = random_cells(rng)
    nxt, plus, minus = ref.step(field, cell, transfer)
    before = ref.flux_w(field)
    after = ref.flux_w(nxt) + plus.sum() + minus.sum()
    assert after <= before * (1 + 1e-12)
    assert np.all(plus >= 0) and np.all(minus >= 0)
    # Every face's outflow is >= 0, so the next field's flux per cell is too.
    assert np.all(nxt[..., 0] >= -1e-15)


@pytest.mark.parametrize("transfer", ref.TRANSFERS)
def test_a_closed_box_keeps_all_of_its_light(transfer):
    # A shell of fully blocking cells (projected area 1 on every axis) around an empty interior: all the
    # interior sends into the shell is absorbed, the rest stays inside, so the field's flux plus the
    # absorbed flux stays the emitters' to rounding, step after step.
    dims = (6, 6, 6)
    occ = np.ones(dims, bool)
    occ[1:-1, 1:-1, 1:-1] = False
    cell = ref.cells(occ, np.zeros((*dims, 3)), np.ones((*dims, 3)))
    rng = np.random.default_rng(7)
    field = np.zeros((*dims, 4))
    field[1:-1, 1:-1, 1:-1] = rng.normal(size=(4, 4, 4, 4))
    field[1:-1, 1:-1, 1:-1, 0] = np.abs(field[1:-1, 1:-1, 1:-1, 0]) + 2.0
    total = ref.flux_w(field)
    absorbed = 0.0
    for _ in range(4):
        field, plus, minus = ref.step(field, cell, transfer)
        absorbed += plus.sum() + minus.sum()
        assert ref.flux_w(field) + absorbed == pytest.approx(total, rel=1e-12)


@pytest.mark.parametrize("seed", range(3))
def test_the_directional_faces_carry_the_field_itself(seed):
    # The directional transfer moves M_d L through face d and sum_d M_d = 1, so the faces together must
    # carry L: the light keeps its direction. With band 1 up to 3 c0 some faces' flux is negative and is
    # clamped, and some faces are closed; their lobes' direction is shared out over the carrying faces,
    # so the sum of what the faces carry is still the cell's field, to float64 rounding. Only cells that
    # send anything are compared (c0 > 0 and a carrying face).
    rng = np.random.default_rng(seed)
    field = rng.normal(size=(*DIMS_ZYX, 4))
    field[..., 0] = np.abs(field[..., 0])
    cell = random_cells(rng)
    out = ref.face_fluxes(field, cell["open"], "directional")
    carried = np.einsum("...d,...dk->...k", out, ref.carried_shapes(field, cell["open"], out, "directional"))
    sends = out.sum(-1) > 0
    assert sends.mean() > 0.5
    clamped = (ref.face_transport(field, "directional")[0] <= 0).any(-1) | ~cell["open"].all(-1)
    assert (sends & clamped).mean() > 0.2  # the case that needs the residual is well represented
    np.testing.assert_allclose(carried[sends], field[sends], rtol=1e-12, atol=1e-12)


def test_a_lambertian_lobe_leaves_a_cell_as_its_directions_do():
    # An upward Lambertian lobe in an open cell: its directions w, each through face d by
    # max(0, w.d) / |w|_1 (the partition M_d projects), send 0.4495 of the flux up and 0.1376 through each
    # side (midpoint quadrature of 4M directions: exact to ~1e-5). The directional transfer's flux row
    # (diffusion_propagate.flux_cross) is set so its L1 field does the same; LPV's m_cross there sent
    # 0.370 up. 1e-4: the quadrature behind flux_cross against this one.
    dirs, weights = sh.sphere_quadrature(1024, 4096)
    cosine = np.maximum(dirs[:, 2], 0.0) / np.pi
    share = np.maximum(dirs @ ref.DIRECTIONS.T, 0.0) / np.abs(dirs).sum(axis=1, keepdims=True)
    exact = (weights * cosine) @ share
    field = (sh.cosine_lobe_l1(np.array([0.0, 0.0, 1.0])) / np.pi).reshape(1, 1, 1, 4)
    got = ref.face_fluxes(field, np.ones((1, 1, 1, 6), bool), "directional")[0, 0, 0] / ref.flux_w(field)
    np.testing.assert_allclose(got, exact, atol=1e-4)
    assert exact[4] == pytest.approx(0.4495, abs=1e-4)


def test_a_lit_floor_hardly_lights_itself():
    # A 10 x 10 lit patch on the floor of a closed 16-cell box (black walls, one bounce, 32 steps, when
    # all of it has been absorbed). Exact: the floor, a plane, gets 0; the ceiling the patch's view factor
    # to it, 0.214 (tools/diffusion_box.py). The L1 transport spreads light sideways, so some comes back
    # down: measured 0.002 on the floor, 0.202 on the ceiling. With LPV's flux row (m_cross, not
    # flux_cross: a Lambertian lobe sent 0.370 of its flux up, not 0.449) 0.047 and 0.181; dropping the
    # clamped faces' lobes (scaling the rest to the flux) turned the field above the floor downward:
    # 0.102 and 0.104. The bounds sit between the measured figures and the previous transfer's.
    n = 16
    cell = ref.closed_box_cells(n)
    lit = np.zeros((n, n, n))
    lit[1, 3:13, 3:13] = 1.0
    field = ref.emit(lit, np.zeros_like(lit), cell["normal"], cell["occupied"])
    total = ref.flux_w(field)
    field, plus, minus = ref.propagate(field, cell, 2 * n, "directional")
    absorbed = plus + minus
    assert absorbed.sum() / total == pytest.approx(1.0, abs=0.002)
    assert absorbed[1, 2:-2, 2:-2].sum() / total < 0.02
    assert absorbed[n - 2, 2:-2, 2:-2].sum() / total > 0.19


@pytest.mark.parametrize("transfer", ref.TRANSFERS)
@pytest.mark.parametrize("cancelled_normal", [False, True])
def test_a_one_cell_wall_stops_light(cancelled_normal, transfer):
    # A wall one cell thick across the whole grid at x = 4 (projected area 1 along x). Its normal is +x,
    # or (cancelled_normal) 0: both faces of a thin wall in one cell, whose mean normal cancels; the
    # cells then take the axis it projects the most along. An isotropic emitter at x = 1: after 40 steps
    # not a bit of light is beyond the wall (exactly 0: the wall absorbs all it gets along x, passes on
    # nothing along y and z since its neighbours there are wall too), and everything the wall absorbed is
    # on its side facing the emitter (the minus side of a +x normal).
    dims = (8, 8, 9)
    occ = np.zeros(dims, bool)
    occ[:, :, 4] = True
    normal = np.zeros((*dims, 3))
    if not cancelled_normal:
        normal[:, :, 4] = (1.0, 0.0, 0.0)
    proj = np.zeros((*dims, 3))
    proj[:, :, 4] = (1.0, 0.0, 0.0)
    cell = ref.cells(occ, normal, proj)
    field = np.zeros((*dims, 4))
    field[4, 4, 1, 0] = 1.0
    total = ref.flux_w(field)
    left, plus, minus = ref.propagate(field, cell, 40, transfer)
    assert not left[:, :, 5:].any()
    assert plus.sum() == 0.0
    # Most of the rest leaves the 8 x 8 cross-section sideways; a fifth reaches the wall (measured 0.25).
    assert 0.2 * total < minus.sum() <= total


def test_emitters_carry_albedo_times_their_flux():
    # A plane's two sides each a clamped-cosine lobe of flux albedo x side flux; an empty cell (a VPL
    # whose surface fell outside every occupied cell) emits its flux isotropically.
    n = np.array([[0.48, -0.6, 0.64], [0.0, 0.0, 0.0]])
    occ = np.array([True, False])
    field = ref.emit(np.array([3.0, 1.0]), np.array([2.0, 0.5]), n, occ, albedo=np.array([0.5, 1.0]))
    assert ref.FLUX_PER_C0 * field[0, 0] == pytest.approx(0.5 * 5.0, rel=1e-14)
    assert ref.FLUX_PER_C0 * field[1, 0] == pytest.approx(1.5, rel=1e-14)
    np.testing.assert_allclose(field[1, 1:], 0.0)
    # The lobe is the clamped cosine about n: band 1 = (3 - 2) x 0.5 / pi x 2 pi / 3 x Y1 x n (y, z, x).
    np.testing.assert_allclose(field[0, 1:], 0.5 * 1.0 / np.pi * sh.BAND_FACTORS[1] * sh.Y1 * n[0, [1, 2, 0]],
                               rtol=1e-14)


def test_an_emitter_against_a_floor_sends_its_light_up_only():
    # A floor of occupied cells: each floor cell's open faces are the one up and (with no cell below the
    # grid) the one down, and its lobe about +z sends nothing down: all its flux goes into the cell above.
    dims = (3, 3, 3)
    occ = np.zeros(dims, bool)
    occ[0] = True
    normal = np.zeros((*dims, 3))
    normal[0] = (0.0, 0.0, 1.0)
    cell = ref.cells(occ, normal, np.where(occ[..., None], [0.0, 0.0, 1.0], 0.0))
    assert cell["open"][0, 1, 1].tolist() == [False, False, False, False, True, True]
    field = ref.emit(np.where(occ, 1.0, 0.0), np.zeros(dims), normal, occ)
    out = ref.face_fluxes(field, cell["open"])
    np.testing.assert_allclose(out[0, 1, 1], [0, 0, 0, 0, 1.0, 0], rtol=1e-14, atol=1e-15)


def lookup_cells(occupied, normal_z=1.0):
    """Cells of floors (normal +z) where `occupied`, both sides of each able to receive light (here no
    empty cell need lie beside them: the lookup's weights are what is tested)."""
    dims = occupied.shape
    normal = np.zeros((*dims, 3))
    normal[occupied] = (0.0, 0.0, normal_z)
    cell = ref.cells(occupied, normal, np.where(occupied[..., None], [0.0, 0.0, 1.0], 0.0))
    cell["receives"] = np.repeat(occupied[..., None], 2, axis=-1)
    return cell


def test_the_lookup_renormalises_over_occupied_cells():
    # Cells with the same irradiance on their plus side, E = flux / (area h^2) = 2 / (1 x 0.25) = 8 W/m^2,
    # read anywhere between them with any subset of the 8 corners occupied: E / pi exactly (the weights
    # are renormalised over the occupied ones); a point whose corners are all empty reads 0 (the defined
    # fallback: no surface near).
    rng = np.random.default_rng(3)
    dims = (2, 2, 2)
    points = rng.random((20, 3)) + 0.5  # between the 8 cell centres
    normals = np.tile([0.0, 0.0, 1.0], (20, 1))
    for k in range(1, 256, 17):
        occ = np.array([(k >> i) & 1 for i in range(8)], bool).reshape(dims)
        cell = lookup_cells(occ)
        value = ref.lookup(points, normals, cell, np.where(occ, 2.0, 0.0), np.zeros(dims), 0.25)
        np.testing.assert_allclose(value, 8.0 / np.pi, rtol=1e-14)
    none = lookup_cells(np.zeros(dims, bool))
    assert not ref.lookup(points, normals, none, np.zeros(dims), np.zeros(dims), 0.25).any()


def test_the_lookup_reads_the_side_facing_the_normal():
    # One occupied cell, 3 W on its plus side (normal +z), 1 W on its minus side: a point facing +z
    # reads 3 / (1 x 1) / pi, facing -z 1 / pi; a point facing +x (perpendicular to the cell's plane:
    # weight |n.n_cell| = 0) falls back to the trilinear weight alone and reads the plus side (ties).
    occ = np.zeros((1, 1, 1), bool)
    occ[0, 0, 0] = True
    cell = lookup_cells(occ)
    pts = np.array([[0.5, 0.5, 0.5]] * 3)
    nrm = np.array([[0, 0, 1.0], [0, 0, -1.0], [1.0, 0, 0]])
    value = ref.lookup(pts, nrm, cell, np.full((1, 1, 1), 3.0), np.full((1, 1, 1), 1.0), 1.0)
    np.testing.assert_allclose(value, np.array([3.0, 1.0, 3.0]) / np.pi, rtol=1e-14)


def test_a_uniform_radiance_gives_its_irradiance_on_any_surface():
    # The receiving area is chosen so a uniform radiance L (W/m^2/sr) reads back E / pi = L whatever the
    # cell holds: a face's one-way inflow from L is pi L h^2, of which `block` is absorbed; here a cell
    # with projected areas (0.7, 0.3, 0) and normal in the xy plane: sides get pi L h^2 (0.7 + 0.3) each.
    occ = np.zeros((3, 3, 3), bool)
    occ[1, 1, 1] = True
    normal = np.zeros((3, 3, 3, 3))
    normal[1, 1, 1] = (0.8, 0.6, 0.0)
    proj = np.zeros((3, 3, 3, 3))
    proj[1, 1, 1] = (0.7, 0.3, 0.0)
    cell = ref.cells(occ, normal, proj)
    h, radiance = 0.5, 2.0
    # Intensity of an isotropic radiance L in a cell: each face's cone carries the face's one-way flux
    # pi L h^2, so c0 = 6 pi L h^2 / (2 sqrt(pi)).
    field = np.zeros((3, 3, 3, 4))
    field[..., 0] = 6.0 * np.pi * radiance * h * h / ref.FLUX_PER_C0
    field[1, 1, 1] = 0.0
    _, plus, minus = ref.step(field, cell)
    assert cell["area"][1, 1, 1] == pytest.approx(1.0)
    assert plus[1, 1, 1] == pytest.approx(minus[1, 1, 1], rel=1e-12)
    points = np.array([[1.5, 1.5, 1.5]] * 2)
    value = ref.lookup(points, np.array([[0.8, 0.6, 0.0], [-0.8, -0.6, 0.0]]), cell, plus, minus, h * h)
    np.testing.assert_allclose(value, radiance, rtol=1e-12)


def _point_source_defect(transfer, measured):
    return pytest.param(transfer, marks=pytest.mark.xfail(strict=True, reason=(
        f"measured: 4 pi r^2 E on the axis falls from {measured} between 4 and 12 cells: light scatters at "
        "every cell and the face transfers favour the axes, so a point source's light does not spread as "
        "1/r^2 (docs/DIFFUSION.md, 'Light diffuses')")))


@pytest.mark.slow  # 120 steps on 41^3 cells: 20 s per transfer
@pytest.mark.parametrize("transfer", [_point_source_defect("cone", "3.42 to 1.64 (x0.48)"),
                                      _point_source_defect("directional", "3.15 to 0.98 (x0.31)")])
def test_a_point_sources_irradiance_falls_as_inverse_square(transfer):
    # Exact: E(r) = (1 W / 4 pi) / (r h)^2 facing the source, so r^2 x the flux a unit-area receiver takes
    # is 1 / (4 pi) at every r; beyond 4 cells (the source's own cell and its neighbours are not a point)
    # to 12 (light from the 41-cell grid's edge, 20 cells out, does not come back) within 10 %.
    flux, _ = ref.point_source_axis_irradiance(transfer=transfer)
    r = np.arange(4, 13)
    np.testing.assert_allclose(4.0 * np.pi * r**2 * flux[r], 1.0, rtol=0.10)


def test_a_point_sources_light_leaves_it_at_one_cell_per_step():
    # What the transport does hold: every watt is either in flight or has crossed the face of the
    # source's neighbourhood (conservation; the grid's edge is 20 cells out and nothing comes back from
    # outside), and no light travels faster than a cell per step: after 3 steps nothing is 4 cells out.
    flux, in_flight = ref.point_source_axis_irradiance(steps=3, size=21)
    assert not flux[4:].any() and flux[3] > 0
    assert in_flight == pytest.approx(1.0, rel=1e-12)


def test_the_lookup_skips_a_side_no_light_can_reach():
    # A floor (z = 0 layer, normal +z) meets a wall (x = 0 column, normal +x) in an edge cell holding both
    # (normal (x + z) / sqrt(2)). Its room side touches no empty cell (floor beside it, wall above), so
    # no light can reach it and its 0 is no reading: a floor point beside it reads the floor cells alone,
    # exactly their irradiance; the edge cell's outer side (empty cells outside the room) can receive.
    dims = (3, 3, 3)
    occ = np.zeros(dims, bool)
    occ[0, :, :] = True
    occ[:, :, 0] = True
    normal = np.zeros((*dims, 3))
    normal[0, :, :] = (0.0, 0.0, 1.0)
    normal[:, :, 0] = (1.0, 0.0, 0.0)
    normal[0, :, 0] = np.array([1.0, 0.0, 1.0]) / np.sqrt(2.0)
    proj = np.zeros((*dims, 3))
    proj[0, :, :, 2] = 1.0
    proj[:, :, 0, 0] = 1.0
    proj[0, :, 0] = (0.5, 0.0, 0.5)
    cell = ref.cells(occ, normal, proj)
    assert cell["receives"][0, 1, 0].tolist() == [False, False]  # (-x, -z are out of the grid here)
    assert cell["receives"][0, 1, 1].tolist() == [True, False] and cell["receives"][1, 1, 0].tolist() == [True, False]
    flux = np.where(occ, 2.0, 0.0)
    flux[0, :, 0] = 0.0  # the edge cell received nothing
    # A floor point between the edge cell (x = 0) and the floor cell x = 1, at the floor's height.
    # And one at the edge cell's very centre (a room's edge or corner vertex), where every other
    # trilinear weight is 0: the weights' floor (LOOKUP_WEIGHT_FLOOR) lets its neighbours answer.
    points = np.array([[0.9, 1.5, 0.5], [0.5, 1.5, 0.5]])
    value = ref.lookup(points, np.array([[0.0, 0.0, 1.0]] * 2), cell, flux, np.zeros(dims), 1.0)
    np.testing.assert_allclose(value, 2.0 / np.pi, rtol=1e-14)


def test_the_far_grid_keeps_a_two_cell_wall_in_one_far_cell():
    # A wall two fine cells thick at x = 1, 2 (and a floor at z = 3, 4) falls across far cells' borders at
    # shift 0 and fills two far cells; starting the far grid one fine cell earlier on those axes puts it
    # in one. Occupancy (z, y, x); the shift is (x, y, z).
    occupied = np.zeros((8, 6, 8), bool)
    occupied[:, :, 1:3] = True
    occupied[3:5, :, :] = True
    assert diffusion_far_field.best_shift(occupied) == (1, 0, 1)
    occupied[:, :, 1:3] = False
    occupied[:, :, 2:4] = True
    assert diffusion_far_field.best_shift(occupied) == (0, 0, 1)
    far = diffusion_far_field.grid_for(Grid(np.zeros(3), 0.5, (7, 6, 8)), (1, 0, 1))
    assert far.grid.dims == (4, 3, 5) and far.grid.cell_size_m == 1.0  # covers fine cells -1 .. 7 on x
    np.testing.assert_allclose(far.grid.origin_m, [-0.5, 0.0, -0.5])


@pytest.mark.parametrize("shift", [(0, 0, 0), (1, 1, 0)])
def test_the_far_field_reads_an_evenly_lit_floor_evenly(shift):
    # A floor one fine cell thick (layer z = 1, normal +z) and its far cells (layer 0) that absorbed 4 W
    # each through face -z (light travelling down): every fine floor cell away from the grid's sides
    # reads the far flux per area, 4 W / 4 fine cells, whatever the tents' alignment, and the fine cells
    # together take exactly the 4 W per far cell. The far cells at the sides reach fewer fine cells
    # (their tents hang over the grid), so the 3 fine cells nearest each side read more; none beyond.
    n = 12
    occupied = np.zeros((4, n, n), bool)
    occupied[1] = True
    normal = np.zeros((4, n, n, 3))
    normal[occupied] = (0.0, 0.0, 1.0)
    cell = ref.cells(occupied, normal, normal)
    far_n = (n + shift[0] + 1) // 2, (n + shift[1] + 1) // 2
    far_occupied = np.zeros((2, far_n[1], far_n[0]), bool)
    far_occupied[0] = True
    far_normal = np.zeros((*far_occupied.shape, 3))
    far_normal[far_occupied] = (0.0, 0.0, 1.0)
    far_cell = ref.cells(far_occupied, far_normal, far_normal)
    faces = np.zeros((*far_occupied.shape, 6))
    faces[0, :, :, 5] = 4.0
    weights = ref.far_weights(far_cell, cell, shift)
    plus, minus = ref.far_add(faces, weights, cell, shift)
    np.testing.assert_allclose(plus[1, 3:-3, 3:-3], 1.0, rtol=1e-12)
    assert np.all(minus == 0) and np.all(plus[[0, 2, 3]] == 0)
    np.testing.assert_allclose(plus.sum(), faces.sum(), rtol=1e-12)
