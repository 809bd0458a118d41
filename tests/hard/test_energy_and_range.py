"""Hard cases 1, 2, 5: energy in a white closed box, dynamic range of light power, a bright light
near a wall. Every shipped method (config.METHODS).

LPV note: the 10,000-step propagation energy test (propagation in a closed grid never gains energy,
and with albedo 1 the total stays bounded) belongs to the LPV propagation pass; `lpv` is not built
yet, so it is not here. Add it to tests/gpu beside the propagation pass when that pass lands.
"""

from __future__ import annotations

import numpy as np
import pytest
from hard_scenes import (
    ALL_METHODS,
    allclose_figure,
    assert_sane,
    box,
    camera,
    make,
    parts,
    point,
    products,
    render,
    room,
    room_camera,
    sanity,
)
from hard_scenes import scene as make_scene

pytestmark = pytest.mark.gpu

FACES = [ax for ax in np.eye(3).tolist() + (-np.eye(3)).tolist()]


# diffusion at 16 cells as well as its default 32: the walls pass through cell centres, so the half
# cells along every edge lie in cells no light can reach and their pixels read the neighbouring cells'
# flux / area: the image reads 1.045 P at 16 cells, beyond the bound (a known defect, conftest.py), and
# 0.947 P at 32 with its far field, 1.001 P on one grid (docs/DIFFUSION.md, "Coarse grids over-read
# near edges", "Far field").
@pytest.mark.parametrize("name", (*ALL_METHODS, "diffusion+cells16"))
def test_white_closed_box_conserves_flux(gl, figures, name):
    # A cube [-1, 1]^3, albedo 1 everywhere, a P = 100 W point light at L = (0.2, -0.1, 0.3) inside.
    # A camera at the centre with six 90-degree faces sees exactly one wall per face, and each pixel of a
    # face covers the same area of its wall (a plane parallel to the image plane), so the surface
    # integral of any output is  A_wall * sum_faces mean(face image)  with A_wall = 4 m^2.
    #
    # Exact answers (closed box: every ray leaving a surface or the light hits the box):
    #   direct:   integral E_d dA = P                      -> pi * sum A mean(direct) = P
    #   indirect: the first bounce reflects rho * P = P (albedo 1) as radiosity B = E_d, and all of it lands
    #             on the box again, so integral E_ind dA = P  (<= P for any 1-bounce method that conserves
    #             energy; the no-visibility RSM gather is exact here because the box is convex).
    #   pointwise: E_ind(y) = integral B/pi cos dw <= max B = max E_d = I / d_min^2, I = P / (4 pi),
    #             d_min = 0.7 m (light to the z = 1 wall), so Diffuse Indirect <= I / (pi d_min^2) = 5.17.
    # Tolerances: the pixel quadrature of the integral is good to 1e-4 (measured on `direct`: 1.0001 P);
    # the gather's Monte Carlo noise on the total over 6 x 48^2 pixels was 0.2 % (64 VPLs): <= 1.02 P.
    # The pointwise bound is checked on 8 x 8 block means (single pixels with 64 VPLs are noisy: a pixel
    # in a corner reached 14.7 with 64 VPLs, 5.76 with 256; that is estimator variance, not energy gain).
    P, light = 100.0, np.array([0.2, -0.1, 0.3])
    geo = parts((*box([-1, -1, -1], [1, 1, 1]), 1.0))
    m = make(gl, name, rsm_res=128, vpl=64)
    sc = make_scene(geo, [point(light, P)], camera([0, 0, 0], FACES[0], size=48, fov_deg=90.0, near=1e-3, far=10))
    m.set_scene(sc)
    totals, block_max = {}, {}
    for axis in FACES:
        sc.camera = camera([0, 0, 0], axis, size=48, fov_deg=90.0, near=1e-3, far=10)
        images = m.run().images
        assert_sane(images)
        assert (images["albedo"][..., 3] == 1).all()  # every pixel sees a wall
        for key, img in products(images).items():
            totals[key] = totals.get(key, 0.0) + np.pi * 4.0 * img[..., :3].mean()
            blocks = img[..., 0].reshape(6, 8, 6, 8).mean(axis=(1, 3))
            block_max[key] = max(block_max.get(key, 0.0), float(blocks.max()))
    bound = P / (4 * np.pi) / (np.pi * 0.7**2)
    flux_bounds = {"direct": "1 ± 1e-3", "indirect": "[0.9, 1.02]"}
    for key in totals:
        figures(f"white box: {key} flux / P", name, totals[key] / P, flux_bounds[key])
        figures(f"white box: max 8x8-block {key}", name, block_max[key], f"≤ {bound:.3g}")
    assert totals["direct"] == pytest.approx(P, rel=1e-3)
    assert block_max["direct"] <= bound
    if "indirect" in totals:
        assert 0.9 * P <= totals["indirect"] <= 1.02 * P, totals
        assert block_max["indirect"] <= bound, block_max


def _range_scene(powers):
    lights = [point([0.4, 0.5, 1.4], powers[0])]
    if len(powers) > 1:
        lights.append(point([-0.5, -0.4, 1.2], powers[1]))
    return make_scene(room(), lights, room_camera())


@pytest.mark.parametrize("name", ALL_METHODS)
def test_dynamic_range_is_linear_in_power(gl, figures, name):
    # Output is linear in light power: out(P) / P == out(1 W) per pixel. fp32 carries relative 6e-8 per
    # operation and 1e9 W gives I = 8e7 W/sr, irradiance ~1e8 W/m^2, VPL flux ~1e3 W per texel: far from
    # fp32's 3.4e38 limit and 1e-6 W far from its 1.2e-38 normal floor. Measured: per-pixel relative error
    # <= 6e-7, so 1e-3 relative (the brief's bound) has a wide margin and still fails on any overflow,
    # flush-to-zero or power-dependent clamp.
    unit = render(gl, name, _range_scene([1.0]))
    for p in (1e-6, 1e9):
        images = render(gl, name, _range_scene([p]))
        assert_sane(images)
        for key, img in products(images).items():
            ref = unit[key][..., :3].astype(np.float64)
            got = img[..., :3].astype(np.float64) / p
            figures(f"linear in power: {key} at {p:g} W vs 1 W, rel error", name,
                    allclose_figure(got, ref, 1e-3, 1e-6 * ref.max()), "≤ 1e-3 (atol 1e-6 max)")
            assert ref.max() > 0
            np.testing.assert_allclose(got, ref, rtol=1e-3, atol=1e-6 * ref.max(), err_msg=f"{key} at {p:g} W")
    # Both together: the 1e-6 W light is 1e-15 of the other, below fp32's resolution, so the image is the
    # 1e9 W image alone (within the same 1e-3), finite, non-negative.
    both = render(gl, name, _range_scene([1e9, 1e-6]))
    alone = render(gl, name, _range_scene([1e9]))
    for key in products(both):
        figures(f"1e9 W + 1e-6 W vs 1e9 W alone: {key} rel error", name,
                allclose_figure(both[key][..., :3], alone[key][..., :3], 1e-3, 1e-6 * float(alone[key].max())),
                "≤ 1e-3 (atol 1e-6 max)")
    assert_sane(both)
    for key in products(both):
        np.testing.assert_allclose(both[key][..., :3], alone[key][..., :3], rtol=1e-3,
                                   atol=1e-6 * float(alone[key].max()))


@pytest.mark.parametrize("name", ALL_METHODS)
def test_bright_light_near_wall_no_negative_or_nan(gl, figures, name):
    # A 1e7 W point light 1 cm in front of the back wall of the room (and 1 mm in front of it): the
    # 1/d^2 peak is ~8e5 W/sr / 1e-4 m^2; a VPL at the wall next to a pixel on the same wall has r -> 0
    # (the disk term A / pi keeps it finite). Exact answer for the sign: every term of both outputs is
    # >= 0, so any negative value or NaN is a defect. The peak of direct is bounded by I / (pi d^2).
    for gap in (1e-2, 1e-3):
        images = render(gl, name, make_scene(room(), [point([0.0, 1.0 - gap, 1.0], 1e7)], room_camera()))
        peak = 1e7 / (4 * np.pi) / (np.pi * gap**2)
        figures(f"1e7 W light {gap:g} m from a wall: outputs", name, sanity(images), "finite, min ≥ 0")
        figures(f"1e7 W light {gap:g} m from a wall: peak direct / (I / π d²)", name,
                images["direct"][..., :3].max() / peak, "(0, 1 + 1e-5]")
        assert_sane(images)
        assert images["direct"][..., :3].max() <= 1e7 / (4 * np.pi) / (np.pi * gap**2) * (1 + 1e-5)
        assert images["direct"][..., :3].max() > 0
