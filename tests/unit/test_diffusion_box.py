"""tools/diffusion_box.py's sharper angular models (--alternatives) hold what the comparison assumes:
each conserves flux, adds nothing, and leaves a Lambertian lobe by its exact face shares, so the twin
compares angular models and nothing else."""

import importlib.util
from pathlib import Path

import numpy as np

from addon.engine import diffusion_reference as ref
from addon.engine import sh

ROOT = Path(__file__).resolve().parents[2]
_spec = importlib.util.spec_from_file_location("diffusion_box", ROOT / "tools" / "diffusion_box.py")
diffusion_box = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(diffusion_box)

# An upward Lambertian lobe's exact share through the top face: the mean of w_z / |w|_1 over the
# cosine lobe (diffusion_propagate.flux_cross integrates it: 0.44946).
LAMBERTIAN_UP_SHARE = 0.44946


def realizable_fields(count: int, seed: int = 0) -> np.ndarray:
    """(count, 1, 1, 4) L1 fields of positive light: a few Lambertian lobes and an isotropic part each."""
    rng = np.random.default_rng(seed)
    fields = np.zeros((count, 1, 1, 4))
    for i in range(count):
        normals = rng.normal(size=(3, 3))
        normals /= np.linalg.norm(normals, axis=-1, keepdims=True)
        weights = rng.random(3) * rng.random()
        fields[i, 0, 0] = (weights[:, None] * sh.cosine_lobe_l1(normals)).sum(0) / np.pi
        fields[i, 0, 0, 0] += rng.random() * 0.3
    return fields


def test_the_closure_partitions_flux_and_direction():
    fields = realizable_fields(40)
    raw, shape = diffusion_box.closure_transfer()(fields)
    flux = ref.FLUX_PER_C0 * fields[..., 0]
    assert raw.min() >= 0.0  # a positive lobe's parts are positive: nothing to clamp
    np.testing.assert_allclose(raw.sum(-1), flux, rtol=1e-12)  # shares of a normalised lobe
    # The faces carry the field's direction: exact for the family, up to the 2000-direction spiral's
    # quadrature of the lobe's first moment (1.2e-5 of the flux on these fields).
    carried = (shape * raw[..., None]).sum(-2)
    np.testing.assert_allclose(carried, fields, atol=1e-4 * flux.max())


def test_the_alternatives_leave_a_lambertian_lobe_by_its_exact_shares():
    up = np.array([0.0, 0.0, 1.0])
    open_faces = np.ones((1, 1, 1, 6))
    for transfer, lobe, tolerance in ((diffusion_box.closure_transfer(), sh.cosine_lobe_l1(up), 1e-3),
                                      (diffusion_box.l2_transfer(), sh.cosine_lobe_l2(up), 3.5e-3),
                                      (diffusion_box.limited_transfer(), sh.cosine_lobe_l1(up), 1e-5)):
        # closure: the cosine power p = 1 itself, to the spiral's quadrature (it reads 0.44948); L2: its
        # projection of the clamped cosine rings below the horizon and leaves 0.4467 up; limited: at its
        # knee the limiter is 1 and the flux row is directional's, exact but for the constant's digits.
        field = (lobe / np.pi).reshape(1, 1, 1, -1)
        shares = ref.face_fluxes(field, open_faces, transfer)[0, 0, 0] / ref.flux_w(field)
        assert abs(shares[4] - LAMBERTIAN_UP_SHARE) < tolerance
        assert shares[5] < 1e-9  # nothing goes down


def test_a_callable_transfer_is_carried_as_directional_is():
    cell = ref.closed_box_cells(6)
    field = realizable_fields(6 ** 3, seed=1).reshape(6, 6, 6, 4) * cell["occupied"][..., None]
    named = ref.step(field, cell, "directional")
    called = ref.step(field, cell, lambda f: ref.face_transport(f, "directional"))
    for a, b in zip(named, called, strict=True):
        np.testing.assert_array_equal(a, b)


def test_the_floor_to_ceiling_share_is_the_view_factor_of_facing_squares():
    # A cube's floor to its ceiling: two directly opposed parallel squares of side a at distance a, whose
    # view factor in closed form (parallel, directly opposed rectangles, X = Y = 1) is 0.199825. A million
    # samples: standard error 4e-4, so 2e-3 is five of them.
    ceiling, on_block = diffusion_box.floor_past_block(19, None)
    assert abs(ceiling - 0.199825) < 2e-3 and on_block == 0.0
    ceiling_past, on_block = diffusion_box.floor_past_block(19, diffusion_box.block_in_box(19))
    assert 0.0 < on_block < 1.0 and ceiling_past < ceiling  # the block shades the ceiling


def test_a_block_stands_on_the_floor_with_its_normals_outwards():
    lo, hi, top = 4, 8, 7
    cell = ref.closed_box_cells(14, (lo, hi, top))
    np.testing.assert_array_equal(cell["normal"][3, 6, lo], (-1.0, 0.0, 0.0))  # a side, mid-height (z, y, x)
    np.testing.assert_array_equal(cell["normal"][3, hi, 6], (0.0, 1.0, 0.0))
    np.testing.assert_array_equal(cell["normal"][top, 6, 6], (0.0, 0.0, 1.0))  # the top
    # 5 x 5 cells across, z 2..7: five layers of its 16-cell ring, then the 25 cells of its top
    assert cell["occupied"][2:top + 1, lo:hi + 1, lo:hi + 1].sum() == 5 * 16 + 25
    assert not cell["occupied"][3, 6, 6]  # the block's inside is air no light reaches


def test_the_limiter_sends_a_beam_through_its_own_face_only_and_keeps_the_field():
    beam = (np.array([sh.Y00, 0.0, sh.Y1, 0.0]) * 0.7).reshape(1, 1, 1, 4)  # a collimated beam up (1, y, z, x)
    shares = ref.face_fluxes(beam, np.ones((1, 1, 1, 6)), diffusion_box.limited_transfer())[0, 0, 0]
    np.testing.assert_allclose(shares / ref.flux_w(beam), [0, 0, 0, 0, 1, 0], atol=1e-12)
    # Any field: the faces together carry the field itself (the residual takes what the clamped faces held).
    fields = realizable_fields(30, seed=2)
    open_faces = np.ones((30, 1, 1, 6))
    out = ref.face_fluxes(fields, open_faces, diffusion_box.limited_transfer())
    np.testing.assert_allclose(out.sum(-1), ref.FLUX_PER_C0 * fields[..., 0], rtol=1e-12)  # all its flux
    shapes = ref.carried_shapes(fields, open_faces, out, diffusion_box.limited_transfer())
    np.testing.assert_allclose((shapes * out[..., None]).sum(-2), fields, rtol=1e-10, atol=1e-15)



def test_l2_by_surfaces_is_l2_at_surfaces_and_directional_in_the_air():
    occupied = np.zeros((5, 5, 5), bool)
    occupied[2, 2, 2] = True  # one surface cell: it and its six neighbours are "near"
    normal = np.zeros((5, 5, 5, 3))
    normal[2, 2, 2] = (0.0, 0.0, 1.0)
    cell = ref.cells(occupied, normal, np.zeros((5, 5, 5, 3)))
    rng = np.random.default_rng(3)
    field = rng.normal(size=(5, 5, 5, 9))
    raw, shape = diffusion_box.surface_l2_transfer().make(cell)(field)
    raw_l2, shape_l2 = diffusion_box.l2_transfer()(field)
    raw_l1, shape_l1 = ref.face_transport(field[..., :4], "directional")
    for near in ((2, 2, 2), (2, 2, 3), (1, 2, 2)):
        np.testing.assert_array_equal(raw[near], raw_l2[near])
        np.testing.assert_array_equal(shape[near], shape_l2[near])
    for air in ((0, 0, 0), (2, 2, 4), (4, 4, 4)):  # two cells off, or further
        np.testing.assert_allclose(raw[air], raw_l1[air], rtol=1e-12)
        np.testing.assert_allclose(shape[air][..., :4], shape_l1[air], rtol=1e-12)
        assert np.all(shape[air][..., 4:] == 0.0)  # the L2 band is dropped in the air


def test_the_sharper_row_is_directional_at_one_and_sends_its_scaled_share_up():
    fields = realizable_fields(20)
    open_faces = np.ones((20, 1, 1, 6))
    np.testing.assert_allclose(ref.face_fluxes(fields, open_faces, diffusion_box.sharper_row_transfer(1.0)),
                               ref.face_fluxes(fields, open_faces, "directional"), rtol=1e-12)
    # An upward Lambertian lobe, per W: each side's raw flux is 1/6, the top's 1/6 + r (its down face
    # clamps), so the top's share is (1/6 + r) / (5/6 + r), the exact share s at scale 1; scaling the
    # row scales r: (1/6 + 1.3 r) / (5/6 + 1.3 r) = 0.49655.
    s = LAMBERTIAN_UP_SHARE
    r = (5.0 * s / 6.0 - 1.0 / 6.0) / (1.0 - s)
    field = (sh.cosine_lobe_l1(np.array([0.0, 0.0, 1.0])) / np.pi).reshape(1, 1, 1, 4)
    shares = (ref.face_fluxes(field, np.ones((1, 1, 1, 6)), diffusion_box.sharper_row_transfer(1.3))[0, 0, 0]
              / ref.flux_w(field))
    # LAMBERTIAN_UP_SHARE is given to 5 digits, so r and the share to about 1e-5.
    assert abs(shares[4] - (1.0 / 6.0 + 1.3 * r) / (5.0 / 6.0 + 1.3 * r)) < 3e-5
    assert abs(shares.sum() - 1.0) < 1e-12 and shares[5] == 0.0
