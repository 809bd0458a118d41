"""The edge-aware a-trous denoise (passes/denoise.py) on synthetic G-buffers: planes laid out in numpy, a
pinhole view of a floor and a sphere ray-cast in numpy, and a lightmap's texel G-buffer rasterized by
the bake pass. Arrays are (h, w, 4); position in metres with w = coverage."""

import numpy as np
import pytest

from addon.engine import metrics
from addon.engine.passes import bake_gbuffer, denoise

pytestmark = pytest.mark.gpu

FOOTPRINT_M = 1.0 / 64  # pixel spacing of the synthetic planes
PARAMS = denoise.Params()


def plane(h, w, origin=(0.0, 0.0, 0.0), ex=(1.0, 0.0, 0.0), ey=(0.0, 1.0, 0.0)):
    """A plane seen orthographically, pixel centres FOOTPRINT_M apart along ex and ey (unit vectors):
    (position, normal) with coverage 1 everywhere."""
    ex, ey = np.asarray(ex, float), np.asarray(ey, float)
    y, x = np.mgrid[0:h, 0:w] + 0.5
    pos = np.ones((h, w, 4))
    pos[..., :3] = np.asarray(origin) + (x[..., None] * ex + y[..., None] * ey) * FOOTPRINT_M
    nrm = np.zeros((h, w, 4))
    nrm[..., :3] = np.cross(ex, ey)
    return pos, nrm


def floor_and_sphere(size=96):
    """A pinhole camera's G-buffer of the floor z = 0 and a sphere of radius 0.5 m resting on it; the sky
    (coverage 0) above the horizon. Silhouettes, a contact crease and curved normals."""
    eye = np.array([0.0, -3.0, 1.2])
    forward = np.array([0.0, 0.0, 0.45]) - eye
    forward /= np.linalg.norm(forward)
    right = np.cross(forward, [0.0, 0.0, 1.0])
    right /= np.linalg.norm(right)
    up = np.cross(right, forward)
    y, x = (np.mgrid[0:size, 0:size] + 0.5) / size * 2.0 - 1.0
    rays = forward + 0.5 * (x[..., None] * right + y[..., None] * up)
    rays /= np.linalg.norm(rays, axis=-1, keepdims=True)
    t_floor = np.where(rays[..., 2] < 0, -eye[2] / np.minimum(rays[..., 2], -1e-9), np.inf)
    centre = np.array([0.0, 0.0, 0.5])
    b = np.sum(rays * (eye - centre), axis=-1)
    disc = b**2 - (np.sum((eye - centre) ** 2) - 0.25)
    t_sphere = np.where(disc > 0, -b - np.sqrt(np.maximum(disc, 0.0)), np.inf)
    t = np.minimum(t_floor, t_sphere)
    hit = np.isfinite(t)
    p = eye + rays * np.where(hit, t, 0.0)[..., None]
    n = np.where((t_sphere < t_floor)[..., None], (p - centre) / 0.5, [0.0, 0.0, 1.0])
    pos = np.zeros((size, size, 4))
    nrm = np.zeros((size, size, 4))
    pos[hit, :3], pos[hit, 3], nrm[hit, :3] = p[hit], 1.0, n[hit]
    return pos, nrm


def on_gpu(backend, position, normal, noisy, params=PARAMS):
    """The pass on `backend`: (h, w, 4) arrays in, the filtered (h, w, 4) array out."""
    size = (position.shape[1], position.shape[0])
    tex = lambda a: backend.texture(size, data=np.asarray(a, np.float32))  # noqa: E731
    gbuf = {"position": tex(position), "normal": tex(normal)}
    out, scratch, guide = backend.texture(size), backend.texture(size), backend.texture(size)
    denoise.run(backend, gbuf, tex(noisy), out, scratch, params, guide=guide)
    return backend.read(out)


def test_flat_field_stays_flat(gl):
    # Every output is sum(w c) / sum(w) over taps of one value c: c up to float32 rounding of the 25-term
    # sums and the division, a few ulp (2^-24 ~ 6e-8 each) per iteration, so rtol 1e-5 over three.
    pos, nrm = floor_and_sphere()
    flat = np.broadcast_to([0.25, 0.5, 2.0, 1.0], pos.shape)
    out = on_gpu(gl, pos, nrm, flat)
    cov = pos[..., 3] > 0
    np.testing.assert_allclose(out[cov], flat[cov], rtol=1e-5)


@pytest.mark.parametrize("right_half", ["depth step", "crease"])
def test_edges_stay_sharp(gl, right_half):
    # Left half: the floor z = 0, value 1. Right half: a parallel plane 0.2 m (13 footprints) below it,
    # or the wall x = 0 rising from the floor's edge (a 90-degree crease seen at 45 degrees), value 0.
    # Neither side may take more than 1e-4 of the other's value (the weights across are exp(-170) and 0).
    h, w = 48, 64
    left, nrm_left = plane(h, w // 2, origin=(-w // 2 * FOOTPRINT_M, 0.0, 0.0))
    if right_half == "depth step":
        right, nrm_right = plane(h, w // 2, origin=(0.0, 0.0, -0.2))
    else:  # the plane through x = 0 spanned by +z and +y: normal -x, facing the floor
        right, nrm_right = plane(h, w // 2, ex=(0.0, 0.0, 1.0), ey=(0.0, 1.0, 0.0))
    pos, nrm = np.concatenate([left, right], axis=1), np.concatenate([nrm_left, nrm_right], axis=1)
    values = np.zeros((h, w, 4))
    values[:, : w // 2] = 1.0
    out = on_gpu(gl, pos, nrm, values)
    assert out[:, w // 2:].max() < 1e-4
    assert out[:, : w // 2].min() > 1.0 - 1e-4


def test_energy_is_kept_over_a_noisy_plane(gl):
    # A tilted plane (not axis-aligned) under a smooth gradient with noise: the filter moves light within
    # the plane but neither adds nor removes it; only the border's renormalised kernels can shift the
    # mean, far below 1 %.
    rng = np.random.default_rng(1)
    h, w = 96, 96
    ex = np.array([0.8, 0.0, 0.6])
    pos, nrm = plane(h, w, origin=(0.3, -0.2, 1.0), ex=ex, ey=(0.0, 1.0, 0.0))
    clean = 1.0 + 0.5 * np.linspace(0.0, 1.0, w)[None, :, None] * np.ones((h, 1, 4))
    noisy = clean + rng.normal(0.0, 0.4, clean.shape)
    out = on_gpu(gl, pos, nrm, noisy)
    assert abs(out[..., :3].mean() / noisy[..., :3].mean() - 1.0) < 0.01


@pytest.mark.parametrize("iterations", [2, 3])
def test_noise_drops_as_the_kernel_says(gl, iterations):
    # On a plane every G-buffer weight is 1 and the geometric iterations (the guided one apart) are the
    # iterations' kernels convolved: i.i.d.
    # noise keeps noise_factor of its standard deviation (0.123 for two iterations, 0.060 for three) at
    # pixels the whole kernel fits around. Measured over >= 228^2 pixels whose outputs are correlated
    # over ~4 pi sigma^2 pixels (the kernel's variance sigma^2 is 5 or 21 px^2 per axis), i.e. >= ~200
    # independent ones, the standard deviation is estimated to ~5 %: demand 80 % of the predicted drop.
    rng = np.random.default_rng(2)
    size = 256
    reach_px = 2 * ((1 << iterations) - 1)  # taps 2 * (1 + 2 + ...) px away
    pos, nrm = plane(size, size)
    clean = np.ones((size, size, 4))
    noisy = clean + rng.normal(0.0, 0.3, clean.shape)
    out = on_gpu(gl, pos, nrm, noisy, denoise.Params(iterations=iterations, guided=False))
    inner = np.zeros((size, size), bool)
    inner[reach_px:-reach_px, reach_px:-reach_px] = True
    before = metrics.rel_rmse(noisy, clean, inner)
    after = metrics.rel_rmse(out, clean, inner)
    predicted_drop = 1.0 / denoise.noise_factor(iterations)
    assert before / after >= 0.8 * predicted_drop, (before, after, predicted_drop)


def test_guided_iteration_averages_the_noise_but_not_a_real_step(gl):
    # A plane (no geometric edge) whose light steps from 1 to 2 halfway, with i.i.d. noise 0.3. Two
    # geometric iterations leave blotches; the guided one averages them where values differ by about the
    # noise and stops where they differ by the step. Measured (rms error against the clean field): away
    # from the step and the border 0.019 against 0.038 for the two iterations alone and 0.018 for a third
    # geometric one; within 4 px of the step 0.238 against 0.255 and 0.351. Bounds: 0.6 x the two
    # iterations' flat noise; at the step no more than the two iterations' + 5 % and below 0.8 x the
    # third geometric iteration's; the mean within 1 % (it was 2e-5).
    rng = np.random.default_rng(4)
    size = 128
    pos, nrm = plane(size, size)
    clean = np.ones((size, size, 4))
    clean[:, size // 2:] = 2.0
    noisy = clean + rng.normal(0.0, 0.3, clean.shape)
    flat = np.zeros((size, size), bool)
    flat[16:-16, 16:size // 2 - 16] = flat[16:-16, size // 2 + 16:-16] = True
    near = np.zeros((size, size), bool)
    near[16:-16, size // 2 - 4:size // 2 + 4] = True

    def errors(params):
        out = on_gpu(gl, pos, nrm, noisy, params)
        rms = [float(np.sqrt(np.mean((out - clean)[m][:, :3] ** 2))) for m in (flat, near)]
        return rms, out[..., :3].mean() / noisy[..., :3].mean()

    (flat_guided, step_guided), energy = errors(denoise.Params(iterations=2))
    (flat_two, step_two), _ = errors(denoise.Params(iterations=2, guided=False))
    (_, step_three), _ = errors(denoise.Params(iterations=3, guided=False))
    print("flat:", flat_guided, flat_two, "step:", step_guided, step_two, step_three)
    assert flat_guided < 0.6 * flat_two
    assert step_guided < 1.05 * step_two
    assert step_guided < 0.8 * step_three
    assert abs(energy - 1.0) < 0.01

def test_iterations_keep_the_reach_a_share_of_the_image():
    # The reach 2 (2^k - 1) px nearest 5 % of the long side: 6 px at 128, 14 at 256, 30 at 512.
    assert [denoise.iterations_for(n) for n in (16, 128, 256, 512, 1024)] == [1, 2, 3, 4, 5]


@pytest.mark.parametrize("iterations", [1, 2, 3, 5])
def test_pass_equals_numpy_reference(gl, iterations):
    # Perspective, silhouettes against the sky, a curved surface and the sphere's contact with the floor:
    # every weight term is exercised. float32 on the GPU against float64: the weights' exp and pow differ
    # by ~1e-6 relative; outputs (values ~1) differed by at most 9e-7 on llvmpipe, so 1e-5 leaves room
    # for other drivers' exp and pow.
    rng = np.random.default_rng(3)
    pos, nrm = floor_and_sphere()
    noisy = rng.uniform(0.0, 2.0, pos.shape) * pos[..., 3:]
    params = denoise.Params(iterations=iterations)
    np.testing.assert_allclose(on_gpu(gl, pos, nrm, noisy, params), denoise.reference(pos, nrm, noisy, params),
                               atol=1e-5)


def test_uncovered_pixels_stay_zero_and_give_nothing(gl):
    # Holes (coverage 0) hold 1000 in the input: they come out exactly 0, and the covered pixels around
    # them, all 1, stay 1 (to float32 rounding): the holes weighed nothing.
    rng = np.random.default_rng(4)
    h, w = 64, 64
    pos, nrm = plane(h, w)
    hole = rng.random((h, w)) < 0.1
    hole[20:30, 10:40] = True
    pos[hole, 3] = 0.0
    values = np.where(hole[..., None], 1000.0, 1.0) * np.ones((h, w, 4))
    out = on_gpu(gl, pos, nrm, values)
    assert np.all(out[hole] == 0.0)
    np.testing.assert_allclose(out[~hole], 1.0, rtol=1e-5)


def test_lightmap_charts_do_not_bleed_across_seams(gl):
    # A texel G-buffer from the bake pass: two charts side by side in UV (columns 2..31 and 32..61 of
    # 64), coplanar in space but 1 m apart (x in [0, 1] and [2, 3]), so only the position term can tell
    # them apart. Chart A holds 1, chart B 0: neither takes more than 1e-4 of the other.
    size = (64, 64)
    lo, mid, hi = 2 / 64, 32 / 64, 62 / 64
    quads = [((lo, mid), (0.0, 1.0)), ((mid, hi), (2.0, 3.0))]  # (u range, world x range)
    uv, positions = [], []
    for (u0, u1), (x0, x1) in quads:
        corners = [(u0, lo, x0, 0.0), (u1, lo, x1, 0.0), (u1, hi, x1, 1.0), (u0, hi, x0, 1.0)]
        for tri in ((0, 1, 2), (0, 2, 3)):
            uv.append([corners[k][:2] for k in tri])
            positions.append([(corners[k][2], corners[k][3], 0.0) for k in tri])
    uv, positions = np.array(uv), np.array(positions)
    normals = np.broadcast_to([0.0, 0.0, 1.0], positions.shape)
    gbuf = {name: gl.texture(size) for name in ("position", "normal", "albedo")}
    attrs = bake_gbuffer.triangle_attributes(uv, positions, normals, np.full((len(uv), 3), 0.8))
    bake_gbuffer.run(gl, bake_gbuffer.target(gl, gbuf), gl.mesh(gl.program(bake_gbuffer.SPEC), attrs, "triangles"),
                     size)
    pos, nrm = gl.read(gbuf["position"]), gl.read(gbuf["normal"])
    cov = pos[..., 3] > 0
    chart_a = cov & (pos[..., 0] < 1.5)
    chart_b = cov & (pos[..., 0] > 1.5)
    assert chart_a.sum() > 1500 and chart_b.sum() > 1500
    values = chart_a[..., None] * np.ones(4)
    out = on_gpu(gl, pos, nrm, values)
    assert out[chart_b].max() < 1e-4
    assert out[chart_a].min() > 1.0 - 1e-4
    assert np.all(out[~cov] == 0.0)


def test_iterations_never_read_what_they_write(gl):
    # An iteration reads one texture and writes another: aliased arguments are refused, and so is a
    # missing scratch or guide texture.
    tex = [gl.texture((4, 4)) for _ in range(5)]
    gbuf = {"position": tex[0], "normal": tex[0]}
    with pytest.raises(ValueError, match="different textures"):
        denoise.run(gl, gbuf, tex[1], tex[1], tex[2], guide=tex[4])
    with pytest.raises(ValueError, match="scratch"):
        denoise.run(gl, gbuf, tex[1], tex[2], None, denoise.Params(iterations=2), guide=tex[4])
    for guide in (None, tex[3]):
        with pytest.raises(ValueError, match="guide"):
            denoise.run(gl, gbuf, tex[1], tex[2], tex[3], guide=guide)


@pytest.mark.parametrize("products", [2, 3])
def test_products_filtered_together_come_out_as_alone(gl, products):
    # One dispatch filters several products with G-buffer weights computed once; the guided iteration's
    # luminance weights stay per product. Each output must equal that product filtered alone: the same
    # float32 operations in the same order, so to rounding (values ~1; 1e-6 allows a compiler's
    # reassociation of the unrolled loops).
    rng = np.random.default_rng(5)
    pos, nrm = floor_and_sphere(64)
    size = (pos.shape[1], pos.shape[0])
    ramp = np.linspace(0.0, 4.0, size[0])[None, :, None]  # a real gradient the guided iteration keeps
    inputs = [rng.uniform(0.0, 2.0, pos.shape) * pos[..., 3:] * (1.0 + k * ramp) for k in range(products)]
    tex = lambda a: gl.texture(size, data=np.asarray(a, np.float32))  # noqa: E731
    gbuf = {"position": tex(pos), "normal": tex(nrm)}
    outs = [gl.texture(size) for _ in inputs]
    denoise.run(gl, gbuf, [tex(a) for a in inputs], outs, [gl.texture(size) for _ in inputs], PARAMS,
                guide=gl.texture(size))
    for image, out in zip(inputs, outs, strict=True):
        np.testing.assert_allclose(gl.read(out), on_gpu(gl, pos, nrm, image), atol=1e-6)


def test_product_lists_must_match(gl):
    # Lists of unequal length, and more products than one dispatch binds, are refused.
    tex = [gl.texture((4, 4)) for _ in range(13)]
    gbuf = {"position": tex[0], "normal": tex[0]}
    with pytest.raises(ValueError, match="as many"):
        denoise.run(gl, gbuf, tex[1:3], tex[3:5], tex[5:6], guide=tex[12])
    with pytest.raises(ValueError, match="products per dispatch"):
        denoise.run(gl, gbuf, tex[1:5], tex[5:9], tex[9:13], guide=tex[0])
