"""LPV passes (inject, propagate, lookup) and the `lpv` method against exact answers.

Units (docs/LPV.md): a cell holds the L1 SH (order 1, y, z, x) of the radiant intensity I(w), W/sr, of
the light leaving it, by direction of travel. The "energy" of a cell is its flux, the integral of the
reconstructed intensity over the sphere: 2 sqrt(pi) c0 (the band-1 terms integrate to 0). It is
linear in the coefficients, so it is conserved (or not) exactly, not up to the L1 projection.
Volumes read back as (z, y, x, 4) arrays.
"""

import numpy as np
import pytest

from addon.engine import lpv_octree_reference as octree_ref
from addon.engine import lpv_reference as ref
from addon.engine import sh
from addon.engine.config import GIConfig, LpvConfig, RsmConfig
from addon.engine.grid import Grid
from addon.engine.methods.lpv import LpvMethod, iterations_for, near_steps_for
from addon.engine.passes import atlas as atlas_pass
from addon.engine.passes import (
    lpv_cascade,
    lpv_far_field,
    lpv_inject,
    lpv_lookup,
    lpv_octree,
    lpv_propagate,
    lpv_reinject,
)
from addon.engine.scene import Camera, Light, Scene
from addon.engine.transforms import look_along, perspective

pytestmark = pytest.mark.gpu


# -- numpy reference of one propagation step (addon/engine/lpv_reference.py) ----------------------------
def reference_step(channels, variant, geometry=None, surface_offsets=True):
    """channels: list of (z, y, x, 4) arrays -> the next snapshot of each (float64). `geometry`:
    {"vox_projected", "vox_offset"} (z, y, x, 4); classic (the published baseline) splits every cell's
    blocking half and half, as LpvVolume does."""
    through = None
    if geometry is not None:
        offsets = geometry["vox_offset"] if surface_offsets and variant == "improved" else None
        through = ref.pass_through(*ref.blocking(geometry["vox_projected"], offsets))
    return [ref.step(c, ref.transfer_matrices(variant), through) for c in channels]


# -- GPU helpers --------------------------------------------------------------------------------------
def volumes(gl, dims, data=None):
    d = data or [None] * 3
    return {f"sh_{c}": gl.texture(dims, "RGBA32F", x) for c, x in zip("rgb", d, strict=True)}


def gpu_steps(gl, grid, channels, variant, steps, geometry=None, surface_offsets=True):
    """Run `steps` propagation steps; returns (snapshots after each step, accumulation) as arrays.
    `geometry`: {"vox_projected", "vox_offset"} arrays (z, y, x, 4) of a geometry volume."""
    sets = [volumes(gl, grid.dims, channels), volumes(gl, grid.dims)]
    acc = {f"acc_{c}": gl.texture(grid.dims) for c in "rgb"}
    gv = None
    if geometry is not None:
        voxels = {k: gl.texture(grid.dims, "RGBA32F", v) for k, v in geometry.items()}
        # As LpvVolume does: classic always splits its blocking half and half.
        gv = lpv_propagate.blocking(gl, voxels, grid, surface_offsets and variant == "improved")
    snaps = []
    for i in range(steps):
        lpv_propagate.run(gl, sets[i % 2], sets[(i + 1) % 2], acc, grid, variant, first_step=i == 0, geometry=gv)
        snaps.append([gl.read(sets[(i + 1) % 2][f"sh_{c}"]) for c in "rgb"])
    return snaps, [gl.read(acc[f"acc_{c}"]) for c in "rgb"]


def random_field(rng, dims, cells=6):
    """Per channel, a few cells each holding a sum of VPL lobes (realizable, non-negative intensity)."""
    out = []
    for _ in range(3):
        v = np.zeros(tuple(reversed(dims)) + (4,), np.float32)
        for _ in range(cells):
            z, y, x = (rng.integers(0, n) for n in reversed(dims))
            n = rng.normal(size=3)
            v[z, y, x] += rng.uniform(0.1, 2.0) * sh.cosine_lobe_l1(n / np.linalg.norm(n)) / np.pi
        out.append(v)
    return out


def flux(channels):
    return np.array([ref.flux_w(c) for c in channels])


# -- injection ----------------------------------------------------------------------------------------
def test_injection_of_one_vpl_gives_its_lobe(gl):
    # Two VPLs in a 4x4 RSM (other texels empty, w = 0) on a 6x5x4 grid of 0.5 m cells at the origin.
    grid = Grid(np.zeros(3), 0.5, (6, 5, 4))
    res = 4
    pos, nrm, phi = (np.zeros((res, res, 4), np.float32) for _ in range(3))
    n1 = np.array([0.3, -0.5, 0.8]) / np.linalg.norm([0.3, -0.5, 0.8])
    p1, f1 = np.array([1.1, 1.3, 0.6]), np.array([2.0, 1.0, 0.5])
    n2 = np.array([0.0, 0.0, -1.0])
    p2, f2 = np.array([2.2, 0.4, 1.9]), np.array([0.25, 0.5, 1.0])
    pos[1, 2] = [*p1, 1.0]
    nrm[1, 2] = [*n1, 0.01]
    phi[1, 2, :3] = f1
    pos[3, 0] = [*p2, 1.0]
    nrm[3, 0] = [*n2, 0.01]
    phi[3, 0, :3] = f2
    rsm = {k: gl.texture((res, res), "RGBA32F", a) for k, a in (("position", pos), ("normal", nrm), ("flux", phi))}
    vols = volumes(gl, grid.dims, [np.full(tuple(reversed(grid.dims)) + (4,), 7.0, np.float32)] * 3)  # stale
    atlas, atlas_tex, target = lpv_inject.atlas_target(gl, grid)
    assert atlas.tiles_x == 2 and atlas.size == (12, 10)  # 4 layers as 2 x 2 tiles: the tiling is exercised
    gl.clear(target)
    lpv_inject.run(gl, target, atlas_pass.texel_points(gl, res, lpv_inject.SPEC), rsm, grid, atlas)
    lpv_inject.unpack(gl, atlas_tex, vols, grid, atlas)
    got = [gl.read(vols[f"sh_{c}"]) for c in "rgb"]

    vpl_pos, vpl_nrm, vpl_flux = np.array([p1, p2]), np.array([n1, n2]), np.array([f1, f2])
    expected = [ref.inject(grid, vpl_pos, vpl_nrm, vpl_flux[:, ch]) for ch in range(3)]
    # The two VPLs land in different layers (tiles), and every other cell's stale content is overwritten.
    assert len(set(ref.injection_cells(grid, vpl_pos, vpl_nrm)[:, 2])) == 2
    for ch in range(3):
        # fp32 arithmetic of a few products: 1e-6 relative to the largest coefficient.
        np.testing.assert_allclose(got[ch], expected[ch], atol=1e-6 * np.abs(expected[ch]).max())
    # The injected flux is the VPLs' flux: 2 sqrt(pi) c0 = phi exactly for a clamped-cosine lobe.
    np.testing.assert_allclose(flux(got), f1 + f2, rtol=1e-6)


def test_emitter_class_is_the_normals_dominant_signed_axis():
    # Classes +x -x +y -y +z -z = 0..5; a tie goes to the earlier axis (x before y before z), as
    # emitter_class.glsl's comparisons do; a zero normal (never a VPL's) is +x.
    normals = np.array([[1, 0, 0], [-1, 0, 0], [0, 1, 0], [0.1, -0.9, 0.2], [0.1, 0.2, 0.97], [0, 0, -1],
                        [0.7071, 0, 0.7071], [0, -0.7071, -0.7071], [0, 0, 0]], float)
    np.testing.assert_array_equal(lpv_inject.emitter_class(normals), [0, 1, 2, 3, 4, 5, 0, 3, 0])


def test_injection_with_emitter_classes_puts_each_vpl_in_its_class_block(gl):
    # 40 VPLs with random normals (and some on the ties between axes) in an 8x8 RSM on a 5x4x3 grid:
    # block k of the atlas must hold exactly the VPLs of class k (numpy's rule, emitter_class), and the
    # six blocks must sum to the injection without classes.
    rng = np.random.default_rng(21)
    grid = Grid(np.zeros(3), 0.5, (5, 4, 3))
    res, count = 8, 40
    n = rng.normal(size=(count, 3))
    n[:6] = [[1, 1, 0], [0, -1, 1], [-1, 0, -1], [1, -1, 1], [0, 0, -1], [-1, 0, 0]]  # ties and axes
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    p = rng.uniform(0.1, 1.4, size=(count, 3)) * np.array([2.5, 2.0, 1.5]) / 1.5
    f = rng.uniform(0.1, 2.0, size=(count, 3))
    pos, nrm, phi = (np.zeros((res, res, 4), np.float32) for _ in range(3))
    texels = rng.choice(res * res, count, replace=False)
    for k, t in enumerate(texels):
        pos.reshape(-1, 4)[t] = [*p[k], 1.0]
        nrm.reshape(-1, 4)[t] = [*n[k], 0.01]
        phi.reshape(-1, 4)[t, :3] = f[k]
    rsm = {k: gl.texture((res, res), "RGBA32F", a) for k, a in (("position", pos), ("normal", nrm), ("flux", phi))}
    vols = volumes(gl, grid.dims)
    blocks = []
    for classes in (True, False):
        atlas, atlas_tex, target = lpv_inject.atlas_target(gl, grid, classes)
        gl.clear(target)
        lpv_inject.run(gl, target, atlas_pass.texel_points(gl, res, lpv_inject.spec(classes)), rsm, grid, atlas,
                       classes)
        for k in range(lpv_inject.CLASSES if classes else 1):
            lpv_inject.unpack(gl, atlas_tex, vols, grid, atlas, k)
            blocks.append([gl.read(vols[f"sh_{c}"]) for c in "rgb"])
    plain, blocks = blocks[-1], blocks[:-1]
    cls = lpv_inject.emitter_class(n)
    assert set(cls) == set(range(6))  # every block is exercised
    cells = ref.injection_cells(grid, p, n)
    inside = np.all((cells >= 0) & (cells < grid.dims), axis=1)
    assert inside.sum() >= 30
    np.testing.assert_allclose(flux(plain), f[inside].sum(axis=0), rtol=1e-5)
    for k, got in enumerate(blocks):
        want = [ref.inject(grid, p[cls == k], n[cls == k], f[cls == k, ch]) for ch in range(3)]
        for ch in range(3):
            # fp32 sums of a few products: 1e-6 of the largest coefficient.
            np.testing.assert_allclose(got[ch], want[ch], atol=1e-6 * np.abs(plain[ch]).max())
    for ch in range(3):
        np.testing.assert_allclose(sum(b[ch] for b in blocks), plain[ch], atol=1e-6 * np.abs(plain[ch]).max())


# -- propagation --------------------------------------------------------------------------------------
@pytest.mark.parametrize("variant", ["classic", "improved"])
def test_gpu_step_equals_numpy_step(gl, variant):
    rng = np.random.default_rng(3)
    grid = Grid(np.zeros(3), 1.0, (7, 6, 5))
    field = random_field(rng, grid.dims, cells=10)
    shape = tuple(reversed(grid.dims)) + (4,)
    occupied = (rng.uniform(size=shape[:3]) < 0.4)[..., None]
    # Projected areas up to 1.5 cells^2 (blocking saturates at 1); offsets across the whole cell and
    # beyond it (the shader clamps the share).
    geometry = {"vox_projected": (rng.uniform(0, 1.5, size=shape) * occupied).astype(np.float32),
                "vox_offset": (rng.uniform(-0.7, 0.7, size=shape) * occupied).astype(np.float32)}
    scale = max(np.abs(c).max() for c in field)
    for gv, offsets in ((None, True), (geometry, False), (geometry, True)):
        snaps, _ = gpu_steps(gl, grid, field, variant, 1, geometry=gv, surface_offsets=offsets)
        want = reference_step(field, variant, gv, offsets)
        for got_c, want_c in zip(snaps[0], want, strict=True):
            # fp32 sums of ~30 products of O(1) values: 1e-5 of the field's scale.
            np.testing.assert_allclose(got_c, want_c, atol=1e-5 * scale)


@pytest.mark.parametrize("variant", ["classic", "improved"])
def test_one_step_never_gains_energy(gl, variant):
    # A field well inside a 9^3 grid (nothing reaches a border in one step): one step keeps the flux
    # exactly (both schemes are flux-conserving: classic's 30 face solid angles sum to 6 x 2 pi / 3
    # = 4 pi with zero first moment, improved's M_d sum to the identity); with a geometry volume it
    # can only lose flux. Tolerance: fp32 accumulation, 1e-5 relative.
    rng = np.random.default_rng(7)
    grid = Grid(np.zeros(3), 1.0, (9, 9, 9))
    field = [np.zeros((9, 9, 9, 4), np.float32) for _ in range(3)]
    inner = random_field(rng, (5, 5, 5), cells=12)
    for f, i in zip(field, inner, strict=True):
        f[2:7, 2:7, 2:7] = i
    before = flux(field)
    snaps, _ = gpu_steps(gl, grid, field, variant, 1)
    after = flux(snaps[0])
    print(f"{variant}: flux before {before}, after one step {after}")
    np.testing.assert_allclose(after, before, rtol=1e-5)
    assert np.all(after <= before * (1 + 1e-5))
    projected = np.zeros((9, 9, 9, 4), np.float32)
    projected[4:6, :, :, 2] = 0.8  # horizontal surfaces across two layers
    offset = np.zeros((9, 9, 9, 4), np.float32)
    offset[4:6, :, :, 2] = [[[0.4]], [[-0.3]]]
    snaps, _ = gpu_steps(gl, grid, field, variant, 1, geometry={"vox_projected": projected, "vox_offset": offset})
    blocked = flux(snaps[0])
    print(f"{variant}: with a geometry volume {blocked}")
    assert np.all(blocked <= before * (1 + 1e-5)) and np.all(blocked < before * 0.999)


@pytest.mark.parametrize("variant", ["classic", "improved"])
def test_open_space_energy_only_leaves_through_the_borders(gl, variant):
    # Flux inside after k steps + flux that crossed the border in steps 1..k = injected. What leaves
    # in a step is what the numpy reference step sends into a one-cell pad around the grid (checked
    # against the GPU step above). fp32 over 12 steps: 1e-5 relative.
    rng = np.random.default_rng(11)
    grid = Grid(np.zeros(3), 1.0, (7, 6, 5))
    field = random_field(rng, grid.dims, cells=8)
    injected = flux(field)
    steps = 12
    snaps, _ = gpu_steps(gl, grid, field, variant, steps)
    left = np.zeros(3)
    prev = field
    for k in range(steps):
        padded = [np.pad(c.astype(np.float64), ((1, 1), (1, 1), (1, 1), (0, 0))) for c in prev]
        nxt = reference_step(padded, variant)
        left += flux(nxt) - flux([c[1:-1, 1:-1, 1:-1] for c in nxt])
        prev = snaps[k]
        np.testing.assert_allclose(flux(snaps[k]) + left, injected, rtol=1e-5)
    print(f"{variant}: after {steps} steps inside {flux(snaps[-1]) / injected}, left {left / injected}")
    assert np.all(left > 0.05 * injected)  # the test measures something: light did reach the borders


def point_source_profile(gl, variant, iterations, length=36, side=31):
    """Diffuse-Indirect-free check of transport: an isotropic 1 W source in an empty grid; irradiance
    on a surface facing it, LPV / exact (I / r^2), at cell centres along +x, by distance in cells."""
    grid = Grid(np.zeros(3), 1.0, (length + 6, side, side))
    src = (4, side // 2, side // 2)  # x, y, z
    field = [np.zeros((side, side, length + 6, 4), np.float32) for _ in range(3)]
    field[0][src[2], src[1], src[0], 0] = 1.0 / ref.FLUX_PER_C0  # P = 1 W in the red channel
    sets = [volumes(gl, grid.dims, field), volumes(gl, grid.dims)]
    acc = {f"acc_{c}": gl.texture(grid.dims) for c in "rgb"}
    for i in range(iterations):
        lpv_propagate.run(gl, sets[i % 2], sets[(i + 1) % 2], acc, grid, variant, first_step=i == 0)
    acc_r = gl.read(acc["acc_r"])
    ratios = {}
    for r in range(1, length + 1):
        c = acc_r[src[2], src[1], src[0] + r]
        e = max(c @ sh.cosine_lobe_l1(np.array([1.0, 0, 0])), 0.0)  # normal -x: lobe about +x
        ratios[r] = e / (1.0 / (4 * np.pi) / r**2)
    return ratios


def test_point_source_irradiance_along_an_axis(gl):
    classic16 = point_source_profile(gl, "classic", 16)
    classic64 = point_source_profile(gl, "classic", 64)
    improved = point_source_profile(gl, "improved", 42 + 31 + 31 - 3)  # its Manhattan-span default
    improved21 = point_source_profile(gl, "improved", 42 + 21 + 21 - 3, side=21)
    show = (1, 2, 4, 8, 12, 16, 24, 32)
    rows = (("classic 16 it", classic16), ("classic 64 it", classic64), ("improved 101 it", improved),
            ("improved, y/z borders at 10 cells", improved21))
    for name, prof in rows:
        print(f"{name}: " + ", ".join(f"{r}: {prof[r]:.2f}" for r in show))
    # classic reproduces BASELINE.md's diagnosis: light counted ~2x near the source and lost far away
    # (BASELINE: 2.99x at 4 cells, 0.05x at 24; the exact figures depend on the lookup and grid).
    assert max(classic64[r] for r in (2, 4, 8)) > 1.8
    assert classic16[24] < 0.1 and classic64[24] < 0.1
    # improved, measured (y/z borders 15 cells away): 0.69 at 1 cell (the source's own cell is not
    # accumulated, and L1 blurs the first step), then 1.27 (2), 1.48 (4), 1.42 (8), 1.55 (12),
    # 1.70 (16), 1.51 (24), 1.57 (32). It is within 2x at every distance, where classic spans
    # 0.00..2.4 and is lost beyond 16 cells. The excess over 1 grows near the borders (borders 10
    # cells away: up to 2.0 at 16 and 2.7 at 32): the L1 transfer carries negative backward lobes,
    # and the border absorbs them along with the positive light. Bound: [0.6, 1.9] on 2..32 cells.
    for r in range(2, 33):
        assert 0.6 <= improved[r] <= 1.9, (r, improved[r])


# -- far field ----------------------------------------------------------------------------------------
def test_far_field_shares_count_every_distance_once():
    # Light in flight for s fine steps is counted by the fine grid with fine_weight(s) and by the coarse
    # grid at its step s / 2 (a coarse step moves light two fine cells) with coarse_weight(s / 2) =
    # 1 - fine_weight(s): the shares sum to exactly 1 at every even time; the fine grid counts everything
    # up to K/2 and nothing from K on, so its last step with a share is K - 1.
    for near in (8, 16, 17, 32):
        for s in range(1, 3 * near):
            w = lpv_far_field.fine_weight(s, near)
            assert 0.0 <= w <= 1.0
            assert w == (1.0 if s <= near / 2 else 0.0 if s >= near else w)
            if s % 2 == 0:
                assert w + lpv_far_field.coarse_weight(s // 2, near) == 1.0


def test_far_field_applies_where_it_is_measured_to_help():
    grid32, grid16 = Grid(np.zeros(3), 0.1, (32, 12, 20)), Grid(np.zeros(3), 0.1, (16, 16, 16))
    assert near_steps_for(LpvConfig(), grid32) == 16  # half the longest side
    assert near_steps_for(LpvConfig(near_steps=10), grid32) == 10
    assert near_steps_for(LpvConfig(far_field=False), grid32) == 0
    assert near_steps_for(LpvConfig(variant="classic"), grid32) == 0  # the published baseline stays as it is
    assert near_steps_for(LpvConfig(), grid16) == 0  # an 8-cell far field resolves too little
    span = iterations_for(LpvConfig(), grid32)
    assert near_steps_for(LpvConfig(near_steps=span), grid32) == 0  # the grid's own steps reach everywhere
    coarse = lpv_far_field.grid_for(Grid(np.array([1.0, 2.0, 3.0]), 0.1, (33, 12, 7)))
    assert coarse.dims == (17, 6, 4) and coarse.cell_size_m == 0.2 and np.array_equal(coarse.origin_m, [1, 2, 3])


def test_far_field_passes_equal_numpy(gl):
    # add: fine += 1/4 x trilinear(coarse) at fine centres (coarse coordinate (i + 0.5) / 2 - 0.5,
    # clamped to the edge); source: coarse = sum of its 2 x 2 x 2 fine cells, those beyond odd fine dims
    # absent. Exact arithmetic up to fp32 rounding: rtol 1e-5 of the largest value.
    rng = np.random.default_rng(7)
    fine = Grid(np.zeros(3), 1.0, (7, 4, 5))
    coarse = lpv_far_field.grid_for(fine)
    fz, fy, fx = reversed(fine.dims)
    cz, cy, cx = reversed(coarse.dims)
    coarse_acc = [rng.normal(size=(cz, cy, cx, 4)).astype(np.float32) for _ in range(3)]
    fine_acc = [rng.normal(size=(fz, fy, fx, 4)).astype(np.float32) for _ in range(3)]
    acc = {f"acc_{c}": gl.texture(fine.dims, "RGBA32F", a) for c, a in zip("rgb", fine_acc, strict=True)}
    far = {f"acc_{c}": gl.texture(coarse.dims, "RGBA32F", a) for c, a in zip("rgb", coarse_acc, strict=True)}
    lpv_far_field.add(gl, far, coarse, acc, fine)

    def corners(n_fine, n_coarse):  # per fine index: (lower corner, upper corner, upper weight)
        t = (np.arange(n_fine) + 0.5) / 2 - 0.5
        i0 = np.floor(t).astype(int)
        return np.clip(i0, 0, n_coarse - 1), np.clip(i0 + 1, 0, n_coarse - 1), t - i0

    (z0, z1, wz), (y0, y1, wy), (x0, x1, wx) = corners(fz, cz), corners(fy, cy), corners(fx, cx)
    for got, before, far_c in zip((gl.read(acc[f"acc_{c}"]) for c in "rgb"), fine_acc, coarse_acc, strict=True):
        want = before.astype(np.float64)
        for kz, az in ((z0, 1 - wz), (z1, wz)):
            for ky, ay in ((y0, 1 - wy), (y1, wy)):
                for kx, ax in ((x0, 1 - wx), (x1, wx)):
                    w = az[:, None, None] * ay[None, :, None] * ax[None, None, :]
                    want += 0.25 * w[..., None] * far_c[np.ix_(kz, ky, kx)]
        np.testing.assert_allclose(got, want, rtol=0, atol=1e-5 * np.abs(want).max())
    snapshot = {f"sh_{c}": gl.texture(fine.dims, "RGBA32F", a) for c, a in zip("rgb", fine_acc, strict=True)}
    out = volumes(gl, coarse.dims)
    lpv_far_field.source(gl, snapshot, fine, out, coarse)
    for c, f in zip("rgb", fine_acc, strict=True):
        padded = np.zeros((2 * cz, 2 * cy, 2 * cx, 4))
        padded[:fz, :fy, :fx] = f
        want = padded.reshape(cz, 2, cy, 2, cx, 2, 4).sum(axis=(1, 3, 5))
        np.testing.assert_allclose(gl.read(out[f"sh_{c}"]), want, rtol=0, atol=1e-5 * np.abs(want).max())


def test_far_field_voxels_equal_numpy(gl):
    # The coarse grid's geometry from the fine voxels: per axis projected area = children's sum / 4
    # (cells^2 of a cell twice as wide), w = summed surface area / 4; offset = the children's surface
    # positions (child centre -+0.5 fine cells + its offset) averaged with the child's projected area
    # along that axis, halved into coarse cells; 0 where no child projects along it. Children beyond odd
    # fine dims are absent. fp32 arithmetic: atol 1e-5.
    rng = np.random.default_rng(11)
    fine = Grid(np.zeros(3), 1.0, (5, 6, 3))
    coarse = lpv_far_field.grid_for(fine)
    fz, fy, fx = reversed(fine.dims)
    cz, cy, cx = reversed(coarse.dims)
    projected = rng.uniform(0, 1.5, (fz, fy, fx, 4)).astype(np.float32)
    projected[..., :3] *= rng.random((fz, fy, fx, 3)) < 0.5  # many children with no surface on an axis
    offset = rng.uniform(-0.5, 0.5, (fz, fy, fx, 4)).astype(np.float32)
    out = lpv_far_field.voxels(gl, {"vox_projected": gl.texture(fine.dims, "RGBA32F", projected),
                                    "vox_offset": gl.texture(fine.dims, "RGBA32F", offset)}, fine, coarse)
    got_p, got_o = gl.read(out["vox_projected"]), gl.read(out["vox_offset"])
    for z, y, x in np.ndindex(cz, cy, cx):
        area, moment, surface = np.zeros(3), np.zeros(3), 0.0
        for dz, dy, dx in np.ndindex(2, 2, 2):
            cz_, cy_, cx_ = 2 * z + dz, 2 * y + dy, 2 * x + dx
            if cz_ >= fz or cy_ >= fy or cx_ >= fx:
                continue
            p = projected[cz_, cy_, cx_]
            position = np.array([dx, dy, dz]) - 0.5 + offset[cz_, cy_, cx_, :3]  # x, y, z
            area += p[:3]
            moment += p[:3] * position
            surface += p[3]
        want_o = np.where(area > 0, 0.5 * moment / np.maximum(area, 1e-30), 0.0)
        np.testing.assert_allclose(got_p[z, y, x], [*(area / 4), surface / 4], atol=1e-5)
        np.testing.assert_allclose(got_o[z, y, x, :3], want_o, atol=1e-5)


def far_field_point_source_profile(gl, near, length=36, side=31):
    """point_source_profile's source and read-out through the far field: the fine grid's near steps
    plus a coarse grid (its source summed from the fine one, as for later bounces) over its span."""
    grid = Grid(np.zeros(3), 1.0, (length + 6, side, side))
    coarse = lpv_far_field.grid_for(grid)
    src = (4, side // 2, side // 2)
    field = [np.zeros((side, side, length + 6, 4), np.float32) for _ in range(3)]
    field[0][src[2], src[1], src[0], 0] = 1.0 / ref.FLUX_PER_C0
    fine_sets = [volumes(gl, grid.dims, field), volumes(gl, grid.dims)]
    coarse_sets = [volumes(gl, coarse.dims), volumes(gl, coarse.dims)]
    lpv_far_field.source(gl, fine_sets[0], grid, coarse_sets[0], coarse)
    acc = {f"acc_{c}": gl.texture(grid.dims) for c in "rgb"}
    far = {f"acc_{c}": gl.texture(coarse.dims) for c in "rgb"}
    for g, sets, out, n, share in ((grid, fine_sets, acc, near - 1, lpv_far_field.fine_weight),
                                   (coarse, coarse_sets, far, sum(coarse.dims) - 3, lpv_far_field.coarse_weight)):
        for i in range(n):
            lpv_propagate.run(gl, sets[i % 2], sets[(i + 1) % 2], out, g, "improved", first_step=i == 0,
                              step_scale=share(i + 1, near))
    lpv_far_field.add(gl, far, coarse, acc, grid)
    acc_r = gl.read(acc["acc_r"])
    return {r: max(acc_r[src[2], src[1], src[0] + r] @ sh.cosine_lobe_l1(np.array([1.0, 0, 0])), 0.0)
            / (1.0 / (4 * np.pi) / r**2) for r in range(1, length + 1)}


def test_far_field_point_source_irradiance_along_an_axis(gl):
    # In open space the far field reads like the single grid: the coarse grid's L1 transfer has the same
    # on-axis excess (it is not a property of the number of steps there). Measured, near = 16, LPV /
    # exact at 1, 2, 4, 8, 12, 16, 24, 32 cells: 0.69, 1.29, 1.66, 0.97, 1.47, 1.80, 1.76, 1.86 (one
    # grid: 0.69, 1.27, 1.48, 1.42, 1.55, 1.70, 1.51, 1.57); the dip at 8 cells is the hand-over
    # (K/2 .. K), where the coarse source sits half a fine cell further out. Bound: the single grid's
    # band [0.6, 1.9] over 2..32 cells, so lost or doubled far light fails.
    far = far_field_point_source_profile(gl, near=16)
    print("far field, near 16: " + ", ".join(f"{r}: {far[r]:.2f}" for r in (1, 2, 4, 8, 12, 16, 24, 32)))
    for r in range(2, 33):
        assert 0.6 <= far[r] <= 1.9, (r, far[r])


# -- lookup -------------------------------------------------------------------------------------------
def reference_lookup(acc, vox_normal, grid, pos, nrm):
    """The numpy twin of lookup.comp.glsl with the geometry volume per colour: E / pi (k, 3); acc: per
    channel (z, y, x, 4); pos, nrm: (k, 3)."""
    return np.stack([ref.lookup(a, grid, pos, nrm, vox_normal) for a in acc], axis=-1)


def test_lookup_skips_the_cells_a_surface_blocks(gl):
    # A wall (normal +x, 1 cell^2 per cell: blocking 1 along x) in the x = 2 layer of a 6x5x4 grid; the
    # cells in front of it (x >= 3) hold light travelling towards it, the wall's own cells a quarter of
    # that. A receiver on the wall, facing +x, samples half a cell out: between its own cell and the one
    # in front. The geometry-aware lookup reads the cell in front only (the wall cells' weight is 0),
    # where plain trilinear reads the mean of both, 0.625 of it. Oblique receivers and a partly blocking
    # cell are checked against the numpy twin.
    rng = np.random.default_rng(9)
    grid = Grid(np.array([-1.0, 0.0, 0.0]), 0.5, (6, 5, 4))
    shape = tuple(reversed(grid.dims))
    toward_wall = sh.cosine_lobe_l1(np.array([-1.0, 0.0, 0.0])) / np.pi
    acc = []
    for ch in range(3):
        v = np.zeros(shape + (4,), np.float32)
        v[..., 3:, :] = (ch + 1.0) * toward_wall
        v[..., :3, :] = 0.25 * (ch + 1.0) * toward_wall
        v += 0.05 * rng.normal(size=v.shape).astype(np.float32)
        acc.append(v)
    vox = np.zeros(shape + (4,), np.float32)
    vox[..., 2, :] = [1.0, 0.0, 0.0, 1.0]
    vox[1, 2, 4] = [0.6, 0.8, 0.0, 0.5]  # a partly blocking oblique surface in front of the wall
    # Receivers: on the wall (x = 0.25 m: mid-cell of layer x = 2; y, z at cell centres) facing +x, and
    # oblique ones.
    pos = np.array([[0.25, 1.25, 0.75], [0.25, 0.75, 1.25], [0.7, 1.1, 0.7], [0.9, 1.3, 0.4]], np.float32)
    nrm = np.array([[1, 0, 0], [1, 0, 0], [0.6, 0.8, 0], [0.5, -0.5, 0.7071]], np.float32)
    k = len(pos)
    gbuf = {"position": gl.texture((k, 1), "RGBA32F", np.c_[pos, np.ones(k)].reshape(1, k, 4).astype(np.float32)),
            "normal": gl.texture((k, 1), "RGBA32F", np.c_[nrm, np.zeros(k)].reshape(1, k, 4).astype(np.float32))}
    tex = {f"acc_{c}": gl.texture(grid.dims, "RGBA32F", a) for c, a in zip("rgb", acc, strict=True)}
    out = gl.texture((k, 1))
    lpv_lookup.run(gl, gbuf, tex, out, grid, vox_normal=gl.texture(grid.dims, "RGBA32F", vox))
    got = gl.read(out)[0, :, :3]
    want = reference_lookup(acc, vox, grid, pos.astype(float), nrm.astype(float))
    # fp32 sums of 8 products; 1e-5 of the largest value.
    np.testing.assert_allclose(got, want, atol=1e-5 * want.max())
    lpv_lookup.run(gl, gbuf, tex, out, grid)  # without the geometry volume: plain trilinear
    plain = gl.read(out)[0, :, :3]
    # On the wall: exactly the cell in front (x = 3) of each receiver, E / pi = c . lobe(-n) / (h^2 pi).
    front = np.array([[a[z, y, 3] @ sh.cosine_lobe_l1(np.array([-1.0, 0, 0])) for a in acc]
                      for z, y in ((1, 2), (2, 1))]) / (0.25 * np.pi)
    np.testing.assert_allclose(got[:2], front, rtol=1e-5)
    print(f"on the wall: aware / plain = {got[:2].sum() / plain[:2].sum():.3f}")
    assert np.all(plain[:2] < 0.8 * got[:2])


def test_lookup_with_emitter_classes_reads_every_class_but_its_own(gl):
    # Six random class volumes C_k and their sum T; receivers of every class, some oblique, under a
    # partly blocking geometry volume. lpv_lookup.own once per class, then the lookup of T with
    # own_light, must read what reference_lookup reads of T - C_r (r the receiver's class): the
    # reading is linear in the volume before its clamp at 0.
    rng = np.random.default_rng(17)
    grid = Grid(np.array([-1.0, 0.0, 0.0]), 0.5, (6, 5, 4))
    shape = tuple(reversed(grid.dims))
    classes = [[rng.normal(size=shape + (4,)).astype(np.float32) for _ in range(3)] for _ in range(6)]
    total = [np.sum([c[ch] for c in classes], axis=0, dtype=np.float32) for ch in range(3)]
    vox = np.zeros(shape + (4,), np.float32)
    vox[..., 2, :] = [1.0, 0.0, 0.0, 0.7]
    k = 24
    pos = rng.uniform([-0.9, 0.1, 0.1], [1.9, 2.4, 1.9], size=(k, 3))
    nrm = rng.normal(size=(k, 3))
    nrm[:6] = ref.DIRECTIONS
    nrm /= np.linalg.norm(nrm, axis=1, keepdims=True)
    gbuf = {"position": gl.texture((k, 1), "RGBA32F", np.c_[pos, np.ones(k)].reshape(1, k, 4).astype(np.float32)),
            "normal": gl.texture((k, 1), "RGBA32F", np.c_[nrm, np.zeros(k)].reshape(1, k, 4).astype(np.float32))}
    vox_tex = gl.texture(grid.dims, "RGBA32F", vox)
    own, out = gl.texture((k, 1)), gl.texture((k, 1))
    for e, c in enumerate(classes):
        tex = {f"acc_{ch}": gl.texture(grid.dims, "RGBA32F", a) for ch, a in zip("rgb", c, strict=True)}
        lpv_lookup.own(gl, gbuf, tex, own, grid, e, vox_normal=vox_tex)
    tex = {f"acc_{ch}": gl.texture(grid.dims, "RGBA32F", a) for ch, a in zip("rgb", total, strict=True)}
    lpv_lookup.run(gl, gbuf, tex, out, grid, vox_normal=vox_tex, own_light=own)
    got = gl.read(out)[0, :, :3]
    cls = lpv_inject.emitter_class(nrm)
    assert set(cls) == set(range(6))
    want = np.array([reference_lookup([t - c for t, c in zip(total, classes[r], strict=True)], vox, grid,
                                      pos[i:i + 1], nrm[i:i + 1])[0] for i, r in enumerate(cls)])
    assert (want > 0).any() and (want == 0).any()  # both sides of the clamp are exercised
    # fp32: the total's and the class's readings (sums of 8 x 4 products of O(6) values) subtracted:
    # 1e-5 of the largest reading of T.
    scale = reference_lookup(total, vox, grid, pos, nrm).max() + want.max()
    np.testing.assert_allclose(got, want, atol=1e-5 * scale)


# -- re-injection (bounces 2..) ----------------------------------------------------------------------
def reference_reinject(acc, vox_normal, vox_albedo, vox_projected, side_acc=None):
    """numpy twin of reinject.comp.glsl: per cell A with a surface, phi = albedo * w * max(0, c . lobe(-m))
    on the better lit side m, c trilinear at A's centre + m / 2 over the corners q weighted by their
    transmittance along m, 1 - min(1, P_q . |m|), renormalised (0 if every corner blocks); sent to A + d
    as phi / pi * lobe(m) x max(0, m.d) / |m|_1. side_acc(m), when given, is the volume each side m reads
    instead of acc (emitter classes: the total less m's class). Returns (snapshot per channel, phi per
    cell (z, y, x, 3))."""
    shape = vox_normal.shape[:3]
    out = [np.zeros(shape + (4,)) for _ in range(3)]
    phi_cells = np.zeros(shape + (3,))

    def arriving(centre_idx, m):
        t = centre_idx + 0.5 * m  # x, y, z in cell-index space (centres at integers)
        i0 = np.floor(t).astype(int)
        f = t - i0
        total, weight = np.zeros(3), 0.0
        for corner in np.ndindex(2, 2, 2):
            w = np.prod([f[k] if corner[k] else 1.0 - f[k] for k in range(3)])
            q = np.clip(i0 + corner, 0, np.array(shape[::-1]) - 1)
            through = 1.0 - min(1.0, vox_projected[q[2], q[1], q[0], :3].astype(np.float64) @ np.abs(m))
            read = acc if side_acc is None else side_acc(m)
            total += w * through * np.array([a[q[2], q[1], q[0]] @ sh.cosine_lobe_l1(-m) for a in read])
            weight += w * through
        return np.maximum(total / weight, 0.0) if weight > 1e-4 else np.zeros(3)

    for z, y, x in zip(*np.nonzero(vox_normal[..., 3] > 0), strict=True):
        n = vox_normal[z, y, x, :3].astype(np.float64)
        if not n.any():
            continue
        e = {s: arriving(np.array([x, y, z], float), s * n) for s in (1.0, -1.0)}
        side = 1.0 if e[1.0].sum() >= e[-1.0].sum() else -1.0
        m = side * n
        phi = vox_albedo[z, y, x, :3] * vox_normal[z, y, x, 3] * e[side]
        phi_cells[z, y, x] = phi
        for d in ref.DIRECTIONS:
            share = max(m @ d, 0.0) / np.abs(m).sum()
            bx, by, bz = np.array([x, y, z]) + d.astype(int)
            if share > 0 and 0 <= bx < shape[2] and 0 <= by < shape[1] and 0 <= bz < shape[0]:
                for ch in range(3):
                    out[ch][bz, by, bx] += phi[ch] / np.pi * share * sh.cosine_lobe_l1(m)
    return out, phi_cells


WALLED_IN = (1, 1, 1)  # (z, y, x) of reinject_case's walled-in surface


def reinject_case(rng, dims):
    """An accumulation (lobes of random directions in every cell, so each side of a surface reads
    light) and surfaces in interior cells (their shares stay in the grid): axis-aligned normals, whose
    samples lie on texel faces (trilinear weights 0.5, exact), and oblique ones; one cell whose
    opposite faces cancelled (n = 0); albedos and areas random. Projected areas: random in every cell
    (0..1.2, so some corners block fully, most partly), and one surface cell walled in on every side
    (every corner blocks: it reads 0)."""
    acc = []
    for _ in range(3):
        v = np.zeros(tuple(reversed(dims)) + (4,), np.float32)
        for idx in np.ndindex(*v.shape[:3]):
            n = rng.normal(size=3)
            v[idx] = rng.uniform(0.1, 1.0) * sh.cosine_lobe_l1(n / np.linalg.norm(n)) / np.pi
        acc.append(v)
    vox_normal = np.zeros(tuple(reversed(dims)) + (4,), np.float32)
    vox_albedo = np.zeros_like(vox_normal)
    normals = [np.array(v, float) for v in ((1, 0, 0), (0, -1, 0), (0, 0, 1), (0, 0, -1), (0.6, 0.8, 0),
                                             (-0.48, 0.6, 0.64), (0, 0, 0))]
    for n in normals:
        z, y, x = (int(rng.integers(1, k - 1)) for k in reversed(dims))
        vox_normal[z, y, x] = [*n, rng.uniform(0.3, 2.0)]
        vox_albedo[z, y, x] = [*rng.uniform(0.1, 0.9, 3), 1.0]
    vox_projected = rng.uniform(0.0, 1.2, size=vox_normal.shape).astype(np.float32)
    z, y, x = WALLED_IN
    assert vox_normal[z, y, x, 3] == 0  # not one of the surfaces above (the seeds below)
    vox_normal[z, y, x] = [0.0, 0.0, 1.0, 1.0]
    vox_albedo[z, y, x] = [0.5, 0.5, 0.5, 1.0]
    vox_projected[z - 1:z + 2, y - 1:y + 2, x - 1:x + 2] = 1.0
    return acc, vox_normal, vox_albedo, vox_projected


def test_reinjected_flux_is_albedo_times_irradiance_times_area(gl):
    rng = np.random.default_rng(5)
    grid = Grid(np.zeros(3), 0.25, (6, 7, 5))  # h = 0.25 m: h^2 cancels in phi (w is in cells^2)
    acc, vox_normal, vox_albedo, vox_projected = reinject_case(rng, grid.dims)
    tex = {f"acc_{c}": gl.texture(grid.dims, "RGBA32F", a) for c, a in zip("rgb", acc, strict=True)}
    snapshot = volumes(gl, grid.dims, [np.full_like(acc[0], 7.0)] * 3)  # stale content: must be overwritten
    voxels = {k: gl.texture(grid.dims, "RGBA32F", v) for k, v in
              (("vox_normal", vox_normal), ("vox_albedo", vox_albedo), ("vox_projected", vox_projected))}
    lpv_reinject.run(gl, tex, voxels, snapshot, grid)
    got = [gl.read(snapshot[f"sh_{c}"]) for c in "rgb"]
    want, phi = reference_reinject(acc, vox_normal, vox_albedo, vox_projected)
    # The walled-in surface reads nothing on either side; the cell with n = 0 reflects nothing; of the
    # six others none is walled in (each has a corner that lets light through on its lit side).
    assert np.all(phi[WALLED_IN] == 0)
    assert np.count_nonzero(phi.sum(axis=-1)) == 6
    scale = max(np.abs(w).max() for w in want)
    for got_c, want_c in zip(got, want, strict=True):
        # fp32 products and sums of a few terms: measured 1e-7 of the scale on llvmpipe, which filters
        # in fp32. (A hardware texture unit quantises the oblique normals' trilinear weights to 8 bits,
        # ~4e-3; the axis-aligned ones sample at weights 0.5, exact everywhere.)
        np.testing.assert_allclose(got_c, want_c, atol=1e-6 * scale)
    # Every share stays in the grid, so the snapshot's flux is the reflected flux exactly:
    # 2 sqrt(pi) c0 summed = sum over surfaces of albedo * E * area.
    np.testing.assert_allclose(flux(got), phi.reshape(-1, 3).sum(axis=0), rtol=1e-5)


def test_reinjection_with_emitter_classes_reflects_the_other_classes_light(gl):
    # reinject_case's surfaces under six random class volumes C_k and their total T: lpv_reinject.own once
    # per class, then the re-injection of T with own_front / own_back, must equal numpy's re-injection in
    # which each side m reads T - C_class(m) (the reading is linear before its clamp).
    rng = np.random.default_rng(8)
    grid = Grid(np.zeros(3), 0.25, (6, 7, 5))
    _, vox_normal, vox_albedo, vox_projected = reinject_case(rng, grid.dims)
    shape = tuple(reversed(grid.dims))

    def random_lobes():  # per cell a lobe of random direction and strength, as reinject_case's
        n = rng.normal(size=shape + (3,))
        n /= np.linalg.norm(n, axis=-1, keepdims=True)
        return (rng.uniform(0.1, 1.0, size=shape + (1,)) * sh.cosine_lobe_l1(n) / np.pi).astype(np.float32)

    classes = [[random_lobes() for _ in range(3)] for _ in range(6)]
    total = [np.sum([c[ch] for c in classes], axis=0, dtype=np.float32) for ch in range(3)]
    voxels = {k: gl.texture(grid.dims, "RGBA32F", v) for k, v in
              (("vox_normal", vox_normal), ("vox_albedo", vox_albedo), ("vox_projected", vox_projected))}
    own = {k: gl.texture(grid.dims) for k in ("own_front", "own_back")}
    for e, c in enumerate(classes):
        tex = {f"acc_{ch}": gl.texture(grid.dims, "RGBA32F", a) for ch, a in zip("rgb", c, strict=True)}
        lpv_reinject.own(gl, tex, voxels, own, grid, e)
    snapshot = volumes(gl, grid.dims)
    tex = {f"acc_{ch}": gl.texture(grid.dims, "RGBA32F", a) for ch, a in zip("rgb", total, strict=True)}
    lpv_reinject.run(gl, tex, voxels, snapshot, grid, own=own)
    got = [gl.read(snapshot[f"sh_{c}"]) for c in "rgb"]

    def side_acc(m):
        k = int(lpv_inject.emitter_class(m[None])[0])
        return [t - c for t, c in zip(total, classes[k], strict=True)]

    want, phi = reference_reinject(total, vox_normal, vox_albedo, vox_projected, side_acc)
    plain, _ = reference_reinject(total, vox_normal, vox_albedo, vox_projected)
    assert np.count_nonzero(phi.sum(axis=-1)) >= 4
    scale = max(np.abs(w).max() for w in want)
    assert max(np.abs(w - p).max() for w, p in zip(want, plain, strict=True)) > 0.1 * scale  # classes matter
    for got_c, want_c in zip(got, want, strict=True):
        # fp32 sums of six classes' readings: 1e-5 of the scale.
        np.testing.assert_allclose(got_c, want_c, atol=1e-5 * scale)


# -- the method ---------------------------------------------------------------------------------------
def rect(origin, u, v):
    o, u, v = (np.asarray(a, float) for a in (origin, u, v))
    p = [o, o + u, o + u + v, o + v]
    n = np.cross(u, v) / np.linalg.norm(np.cross(u, v))
    return [[p[0], p[1], p[2]], [p[0], p[2], p[3]]], [n, n]


def corner_scene():
    light = Light("SPOT", [1.0, 0, 1.8], [0, 0, -1], [1, 1, 1], power_w=300.0, spot_size_rad=np.radians(60),
                  spot_blend=0.1)
    cam = Camera(look_along([3.5, 0, 1.2], [-1, 0, -0.2], [0, 0, 1]), perspective(np.radians(50), 0.1, 100), 24, 24)
    rects = [rect([0, -1, 0], [2, 0, 0], [0, 2, 0]), rect([0, -1, 0], [0, 2, 0], [0, 0, 2])]
    tris, normals, alb = [], [], []
    for (t, n), a in zip(rects, ([0.8, 0.5, 0.2], [0.5, 0.5, 0.5]), strict=True):
        tris += t
        normals += [[ni] * 3 for ni in n]
        alb += [a] * len(t)
    return Scene(np.array(tris, np.float32), np.array(normals, np.float32), np.array(alb, np.float32),
                 np.zeros((len(tris), 3), np.float32), [light], camera=cam)


@pytest.mark.parametrize("variant, classes, bounces", [("classic", False, 1), ("improved", False, 1),
                                                       ("improved", True, 1), ("improved", True, 2),
                                                       ("octree", False, 1), ("octree", False, 2)])
def test_method_output_is_finite_and_non_negative(gl, variant, classes, bounces):
    method = LpvMethod(gl, GIConfig(method="lpv", bounces=bounces), RsmConfig(resolution=64),
                       LpvConfig(grid_cells=12, variant=variant, geometry_volume=True, emitter_classes=classes))
    method.set_scene(corner_scene())
    result = method.run()
    ind = result.images["indirect"][..., :3]
    cover = result.images["indirect"][..., 3] > 0.5
    assert np.all(np.isfinite(ind)) and ind.min() >= 0.0
    assert ind[cover].mean() > 0.0  # the wall sees the lit floor
    assert set(result.timings_ms) >= {"lpv_inject", "lpv_propagate", "lpv_lookup", "total"}


def test_default_constructor_keeps_existing_callers_working(gl):
    method = LpvMethod(gl, GIConfig(method="lpv"), RsmConfig(resolution=32))
    assert method.lpv_config == LpvConfig()


def lone_floor_scene():
    """A 2 m floor (normal +z) lit by a spot above it, nothing else: no surface it can light."""
    light = Light("SPOT", [0.2, 0.1, 1.5], [0, 0, -1], [1, 1, 1], power_w=300.0, spot_size_rad=np.radians(70),
                  spot_blend=0.1)
    cam = Camera(look_along([2.0, 0, 1.5], [-1, 0, -0.8], [0, 0, 1]), perspective(np.radians(60), 0.1, 100), 24, 24)
    tris, n = rect([-1, -1, 0], [2, 0, 0], [0, 2, 0])
    return Scene(np.array(tris, np.float32), np.array([[ni] * 3 for ni in n], np.float32),
                 np.full((len(tris), 3), 0.8, np.float32), np.zeros((len(tris), 3), np.float32), [light], camera=cam)


@pytest.mark.parametrize("grid_cells", [16, 32])
def test_emitter_classes_keep_a_floors_own_light_off_it(gl, grid_cells):
    # A planar floor cannot light itself: Cycles' indirect on it is exactly 0. With emitter classes
    # all its VPLs are of class +z, the total equals that class bit for bit (the other classes add 0),
    # and every floor pixel subtracts its own class's reading, computed by the same code: exactly 0,
    # on one grid (16 cells) and through the far field (32). Without classes the floor reads some of
    # its own light (the L1 lobe of light travelling along the floor reads into the lower hemisphere):
    # measured up to 0.18 / 0.23 (mean 0.046 / 0.12) at 16 / 32 cells.
    images = {}
    for classes in (True, False):
        method = LpvMethod(gl, GIConfig(method="lpv", resolution=32), RsmConfig(resolution=64),
                           LpvConfig(grid_cells=grid_cells, emitter_classes=classes))
        method.set_scene(lone_floor_scene())
        images[classes] = method.run().images["indirect"]
    cover = images[True][..., 3] > 0.5
    assert cover.mean() > 0.3  # the camera sees the floor
    assert np.all(images[True][..., :3] == 0.0)
    assert images[False][..., :3][cover].max() > 0.0


def box_scene():
    """A closed 2 m box (normals inward, a colour per wall), lit by a spot under its ceiling; the camera
    inside sees the far wall, floor, ceiling and side walls."""
    light = Light("SPOT", [0, 0, 1.9], [0, 0, -1], [1, 1, 1], power_w=300.0, spot_size_rad=np.radians(60),
                  spot_blend=0.1)
    cam = Camera(look_along([0.9, 0, 1.0], [-1, 0, 0], [0, 0, 1]), perspective(np.radians(80), 0.05, 100), 24, 24)
    walls = [  # (rect, albedo)
        (rect([-1, -1, 0], [2, 0, 0], [0, 2, 0]), [0.8, 0.5, 0.2]),  # floor
        (rect([-1, -1, 2], [0, 2, 0], [2, 0, 0]), [0.5, 0.5, 0.5]),  # ceiling
        (rect([-1, -1, 0], [0, 2, 0], [0, 0, 2]), [0.7, 0.7, 0.7]),  # x = -1, the far wall
        (rect([1, -1, 0], [0, 0, 2], [0, 2, 0]), [0.6, 0.6, 0.6]),
        (rect([-1, -1, 0], [0, 0, 2], [2, 0, 0]), [0.7, 0.2, 0.2]),  # y = -1, red
        (rect([-1, 1, 0], [2, 0, 0], [0, 0, 2]), [0.2, 0.7, 0.2]),  # y = +1, green
    ]
    tris, normals, alb = [], [], []
    for (t, n), a in walls:
        tris += t
        normals += [[ni] * 3 for ni in n]
        alb += [a] * len(t)
    return Scene(np.array(tris, np.float32), np.array(normals, np.float32), np.array(alb, np.float32),
                 np.zeros((len(tris), 3), np.float32), [light], camera=cam)


def slab(lo, hi):
    """The 6 outward-facing rects (two triangles each) of the box [lo, hi]."""
    lo, hi = np.asarray(lo, float), np.asarray(hi, float)
    x, y, z = (np.eye(3)[i] * (hi - lo)[i] for i in range(3))
    return [rect(lo, z, y), rect(lo + x, y, z), rect(lo, x, z), rect(lo + y, z, x), rect(lo, y, x), rect(lo + z, x, y)]


def thick_room_scene(wall_m=0.1):
    """A closed 2 x 2 x 2 m room whose six walls are solid slabs `wall_m` thick (their inner faces do not
    fall on cell centres the way Grid.fit places the bounds' faces), a 200 W point lamp inside; the
    camera inside looks at the far wall, floor and ceiling."""
    t = wall_m
    slabs = [([-1 - t, -1 - t, -t], [1 + t, 1 + t, 0]), ([-1 - t, -1 - t, 2], [1 + t, 1 + t, 2 + t]),
             ([-1 - t, -1 - t, 0], [-1, 1 + t, 2]), ([1, -1 - t, 0], [1 + t, 1 + t, 2]),
             ([-1, -1 - t, 0], [1, -1, 2]), ([-1, 1, 0], [1, 1 + t, 2])]
    tris, normals = [], []
    for lo, hi in slabs:
        for t_, n in slab(lo, hi):
            tris += t_
            normals += [[ni] * 3 for ni in n]
    k = len(tris)
    light = Light("POINT", [0.3, 0.2, 1.5], [0, 0, -1], [1, 1, 1], power_w=200.0)
    cam = Camera(look_along([0.9, 0, 1.0], [-1, 0, -0.1], [0, 0, 1]), perspective(np.radians(80), 0.05, 100), 24, 24)
    return Scene(np.array(tris, np.float32), np.array(normals, np.float32), np.full((k, 3), 0.7, np.float32),
                 np.zeros((k, 3), np.float32), [light], camera=cam)


def test_surface_offsets_make_light_less_dependent_on_wall_alignment(gl):
    # The same room at six grid sizes: the walls' inner faces fall at other places in their cells each
    # time. Mean indirect light of the view, measured (llvmpipe): without surface offsets 1.62, 0.91,
    # 0.94, 2.04, 2.05, 2.07 (max / min 2.29: at 17 and 20 cells the VPLs land in their own walls'
    # cells and lose half their light on the first step out); with them 1.92, 1.64, 1.40, 2.06, 2.04,
    # 2.04 (1.47). Bounds between the two, so a regression of either fails.
    spreads = {}
    for offsets in (False, True):
        means = []
        for cells in (14, 17, 20, 23, 26, 29):
            method = LpvMethod(gl, GIConfig(method="lpv"), RsmConfig(resolution=64),
                               LpvConfig(grid_cells=cells, surface_offsets=offsets))
            method.set_scene(thick_room_scene())
            ind = method.run().images["indirect"]
            means.append(float(ind[..., :3][ind[..., 3] > 0.5].mean()))
        spreads[offsets] = max(means) / min(means)
        print(f"surface_offsets={offsets}: mean indirect {np.round(means, 3)}, max / min {spreads[offsets]:.3f}")
    assert spreads[True] <= 1.6
    assert spreads[False] >= 2.0


def first_and_second_bounce_flux(gl, geometry_volume, grid_cells=16, far_field=True):
    """(flux the VPLs inject, flux the surfaces reflect of the first bounce) per colour, W, in the box
    scene: a bounces=2 update, whose snapshot set 0 holds the second bounce's source at the end."""
    method = LpvMethod(gl, GIConfig(method="lpv", bounces=2), RsmConfig(resolution=64),
                       LpvConfig(grid_cells=grid_cells, variant="improved", geometry_volume=geometry_volume,
                                 far_field=far_field))
    method.set_scene(box_scene())
    method.compute()
    injected = volumes(gl, method.grid.dims)
    lpv_inject.unpack(gl, method.inject_atlas, injected, method.grid, method.atlas)
    return (flux([gl.read(injected[f"sh_{c}"]) for c in "rgb"]),
            flux([gl.read(method.snapshots[0][f"sh_{c}"]) for c in "rgb"]))


def test_second_bounce_gains_no_energy(gl):
    # In a closed box every watt the first bounce emits lands on a surface once, so the surfaces reflect
    # at most albedo_max (per colour, the box's largest albedo: 0.8, 0.7, 0.7) of it. LPV does not
    # guarantee this (it counts light passing through cells), so it is measured: with the geometry
    # volume the surfaces reflect 0.69, 0.68, 0.53 of the injected flux (the area-weighted albedo is
    # 0.6, 0.5, 0.4; 0.62, 0.61, 0.48 when the re-injection read its own cell too, plain trilinear).
    # Without it light crosses the walls and reaches surfaces it should not: 0.75, 0.74, 0.59, above
    # the bound in green and blue -- the gain this test exists to catch (0.96, 0.94, 0.74 with the
    # plain re-injection; if that assertion starts failing, the leak is fixed: bound it like the
    # geometry volume's case).
    albedo_max = np.array([0.8, 0.7, 0.7])
    injected, reflected = first_and_second_bounce_flux(gl, geometry_volume=True)
    print(f"with GV: reflected / injected = {reflected / injected}")
    _, leaky = first_and_second_bounce_flux(gl, geometry_volume=False)
    print(f"without GV: reflected / injected = {leaky / injected}")
    assert np.all(reflected <= albedo_max * injected)
    assert np.all(reflected > 0.3 * injected)  # and the bounce is there
    assert np.any(leaky > albedo_max * injected)
    # At 32 cells the far field applies (16 near steps, a 16-cell far field): 0.59, 0.58, 0.45. One
    # 32-cell grid reflects 0.76, 0.75, 0.58 -- over the bound in green and blue: every step at a wall
    # adds a little (the L1 transfer's negative backward lobes are absorbed there with the positive
    # light), and the far field takes half as many steps beyond its near field.
    injected, reflected = first_and_second_bounce_flux(gl, geometry_volume=True, grid_cells=32)
    print(f"32 cells, far field: reflected / injected = {reflected / injected}")
    assert np.all(reflected <= albedo_max * injected)
    assert np.all(reflected > 0.3 * injected)


def test_more_bounces_only_add_light(gl):
    # Every later bounce adds light: bounces=2 >= bounces=1 at every pixel, up to fp32 (1e-5 of the
    # largest value). Each bounce is looked up and clamped at 0 on its own: clamping the summed volume
    # instead let the second bounce's negative L1 ringing darken 9 pixel channels of this view (by up
    # to 0.0023, the brightest being 0.39), which this catches. The mean grows by 1.45x here (measured).
    # bounces=1 is unchanged by the multi-bounce code: it is exactly the first bounce of a bounces=2
    # run, and runs no voxelizer and no re-injection unless the geometry volume asks for the voxels.
    runs = {}
    for bounces in (1, 2):
        method = LpvMethod(gl, GIConfig(method="lpv", bounces=bounces), RsmConfig(resolution=64),
                           LpvConfig(grid_cells=16, variant="improved", geometry_volume=True))
        method.set_scene(box_scene())
        runs[bounces] = method, method.run()
    one, two = (runs[b][1].images["indirect"][..., :3] for b in (1, 2))
    cover = runs[1][1].images["indirect"][..., 3] > 0.5
    print(f"mean indirect: 1 bounce {one[cover].mean():.4f}, 2 bounces {two[cover].mean():.4f}")
    assert np.all(two >= one - 1e-5 * one.max())
    assert two[cover].mean() > 1.1 * one[cover].mean()
    assert "lpv_reinject" not in runs[1][1].timings_ms and "lpv_reinject" in runs[2][1].timings_ms
    method2 = runs[2][0]
    for c in "rgb":
        first = gl.read(method2.accumulated[f"acc_{c}"]) - gl.read(method2.bounce_accumulated[f"acc_{c}"])
        alone = gl.read(runs[1][0].accumulated[f"acc_{c}"])
        # total - bounce 2 = bounce 1 up to the rounding of one fp32 add: 1e-6 of the largest coefficient.
        np.testing.assert_allclose(first, alone, atol=1e-6 * np.abs(alone).max())
    plain = LpvMethod(gl, GIConfig(method="lpv"), RsmConfig(resolution=32), LpvConfig(geometry_volume=False))
    plain.set_scene(box_scene())
    assert plain.voxels is None and plain.bounce_accumulated is None


# -- cascades -----------------------------------------------------------------------------------------
def box_faces(lo, hi):
    lo, hi = np.asarray(lo, float), np.asarray(hi, float)
    dx, dy, dz = np.diag(hi - lo)
    return [rect(lo, dy, dx), rect(lo + dz, dx, dy), rect(lo, dx, dz), rect(lo + dy, dz, dx), rect(lo, dz, dy),
            rect(lo + dx, dy, dz)]


def long_floor_scene(res=32):
    """A 20 x 6 m floor with a wall at its far end (x = 0) and four 1 m boxes along it; a strong spot over
    the far end, a weaker one near the camera, which stands at x = 19.5 looking back down the floor."""
    lights = [Light("SPOT", [1.5, 0, 3.0], [0, 0, -1], [1, 1, 1], power_w=2000.0, spot_size_rad=np.radians(90),
                    spot_blend=0.1),
              Light("SPOT", [16.0, 0.5, 2.0], [0, 0, -1], [1, 0.9, 0.8], power_w=200.0,
                    spot_size_rad=np.radians(70), spot_blend=0.1)]
    cam = Camera(look_along([19.5, -1.5, 1.6], [-1, 0.25, -0.3], [0, 0, 1]), perspective(np.radians(60), 0.05, 100),
                 res, res)
    parts = [(rect([0, -3, 0], [20, 0, 0], [0, 6, 0]), [0.8, 0.8, 0.8]),
             (rect([0, -3, 0], [0, 6, 0], [0, 0, 3]), [0.7, 0.7, 0.7])]
    for x, col in ((5, [0.8, 0.3, 0.3]), (10, [0.3, 0.8, 0.3]), (15, [0.3, 0.3, 0.8]), (17.5, [0.8, 0.8, 0.3])):
        parts += [(f, col) for f in box_faces([x, -0.5, 0], [x + 1, 0.5 + (x == 17.5), 1.2])]
    tris, normals, alb = [], [], []
    for (t, n), a in parts:
        tris += t
        normals += [[ni] * 3 for ni in n]
        alb += [a] * len(t)
    return Scene(np.array(tris, np.float32), np.array(normals, np.float32), np.array(alb, np.float32),
                 np.zeros((len(tris), 3), np.float32), lights, camera=cam)


def cascaded(gl, cascades, grid_cells=32, cell_size_m=0.0, scene=None, bounces=1):
    method = LpvMethod(gl, GIConfig(method="lpv", bounces=bounces), RsmConfig(resolution=64),
                       LpvConfig(grid_cells=grid_cells, variant="improved", geometry_volume=True, cascades=cascades,
                                 cell_size_m=cell_size_m))
    method.set_scene(long_floor_scene() if scene is None else scene)
    return method, method.run()


def receivers(gl, pos, nrm):
    k = len(pos)
    return {"position": gl.texture((k, 1), "RGBA32F", np.c_[pos, np.ones(k)].reshape(1, k, 4).astype(np.float32)),
            "normal": gl.texture((k, 1), "RGBA32F", np.c_[nrm, np.zeros(k)].reshape(1, k, 4).astype(np.float32))}


def line_lookups(gl, method, pos, nrm):
    """Along receivers (pos, nrm): (blended chain as the method runs it, finest alone, its parent alone),
    each (k, 3) E / pi; two cascades."""
    fine, parent = method.levels
    gbuf = receivers(gl, pos, nrm)
    out = gl.texture((len(pos), 1))

    def look(level, cascade=None):
        lpv_lookup.run(gl, gbuf, level.accumulated, out, level.grid, vox_normal=method.lookup_vox(level),
                       cascade=cascade)
        return gl.read(out)[0, :, :3].astype(np.float64)

    coarse = look(parent)
    blended = look(fine, fine.cascade)
    return blended, look(fine), coarse


def test_cascade_placement_nests_and_fits():
    lo, hi = np.array([-10.0, -3.0, -1.5]), np.array([10.0, 3.0, 1.5])
    chain = lpv_cascade.place(lo, hi, [9.5, -1.5, 0.1], 32, 3)
    coarsest = Grid.fit(lo, hi, 32)
    assert np.array_equal(chain[-1].grid.origin_m, coarsest.origin_m) and chain[-1].grid.dims == coarsest.dims
    assert chain[-1].grid.dims == (32, 12, 8)  # flat scene, flat grid
    for fine, parent in zip(chain, chain[1:], strict=False):
        assert fine.grid.cell_size_m == parent.grid.cell_size_m / 2
        assert max(fine.grid.dims) <= 32
        lo_f, hi_f = fine.grid.origin_m, fine.grid.origin_m + fine.grid.extent_m
        assert np.all(lo_f >= parent.grid.origin_m - 1e-9)
        assert np.all(hi_f <= parent.grid.origin_m + parent.grid.extent_m + 1e-9)
    assert chain[0].interior_lo[0] == 1 and chain[0].interior_hi[0] == 0  # the camera end of the floor
    # Camera moves within a parent cell: the grids stay; one parent cell further: the finest moves by it.
    h1 = chain[1].grid.cell_size_m
    x0 = chain[0].grid.origin_m[0]
    assert lpv_cascade.place(lo, hi, [9.5 - 0.4 * h1, -1.5, 0.1], 32, 3)[0].grid.origin_m[0] == x0
    assert lpv_cascade.place(lo, hi, [8.0, -1.5, 0.1], 32, 3)[0].grid.origin_m[0] < x0


def fine_region_errors(gl, results, ref):
    """Rel L1 and bias of each run's indirect against `ref` where the finest cascade of results[2] has
    weight 1 (its region, away from the blend band)."""
    method2 = results[2][0]
    fine = method2.levels[0]
    pos = gl.read(method2.gbuf["position"])[::-1]
    nrm = gl.read(method2.gbuf["normal"])[::-1]
    weight = np.zeros(pos.shape[:2])
    for i, j in zip(*np.nonzero(pos[..., 3] > 0), strict=True):
        g = fine.grid.to_grid(pos[i, j, :3] + 0.5 * fine.grid.cell_size_m * nrm[i, j, :3])
        weight[i, j] = lpv_cascade.blend_weight(fine.cascade, g)
    region = weight == 1
    want = ref.images["indirect"][..., :3]
    errors = {}
    for c, (_, result) in results.items():
        ind = result.images["indirect"][..., :3]
        assert np.all(np.isfinite(ind)) and ind.min() >= 0.0
        errors[c] = (np.abs(ind - want)[region].sum() / want[region].sum(), ind[region].sum() / want[region].sum())
    return region, errors


def test_cascades_carry_later_bounces(gl):
    # Two bounces over two cascades (each grid re-injects and propagates the second bounce, the finer one
    # fed its parent's inflow of it). (1) Every later bounce adds light: bounces = 2 >= bounces = 1 at every
    # pixel up to fp32 (1e-5 of the image's maximum). (2) In the finest cascade's region the answer agrees
    # with one grid of the finest cells at two bounces better than one coarse grid at two bounces does.
    # Measured (611 px): rel L1 0.458 (bias 0.56) for one coarse grid, 0.199 (bias 1.14) over cascades.
    one = cascaded(gl, 2)[1].images["indirect"][..., :3]
    results = {c: cascaded(gl, c, bounces=2) for c in (1, 2)}
    two = results[2][1].images["indirect"][..., :3]
    assert np.all(two >= one - 1e-5 * one.max())
    assert two.sum() > 1.01 * one.sum()  # the second bounce is there
    fine = results[2][0].levels[0]
    _, ref = cascaded(gl, 1, grid_cells=64, cell_size_m=fine.grid.cell_size_m, bounces=2)
    region, errors = fine_region_errors(gl, results, ref)
    print(f"two bounces, fine region ({region.sum()} px): rel L1 / bias vs the fine grid "
          f"{ {c: tuple(round(v, 3) for v in e) for c, e in errors.items()} }")
    assert region.sum() > 100
    assert errors[2][0] < 0.7 * errors[1][0]


def test_cascade_blend_has_no_seam(gl):
    # (a) Receivers on the lit floor (facing up, y = -2, clear of the boxes), every 0.05 fine cells along x
    # across the fine cascade's interior face. The blended lookup's largest step between neighbours,
    # relative to the line's mean, stays below STEP_BOUND; a hard switch from the parent to the fine
    # cascade (at the band's start) steps by more.
    method, _ = cascaded(gl, 2)
    fine = method.levels[0]
    assert fine.cascade.interior_lo[0] == 1
    h = fine.grid.cell_size_m
    x = fine.grid.origin_m[0] + h * np.arange(-4.0, 12.0, 0.05)
    floor_z = -method.origin_m[2] + 1e-3  # the floor in the uploaded (re-centred) frame
    pos = np.c_[x, np.full_like(x, -2.0 - method.origin_m[1]), np.full_like(x, floor_z)]
    nrm = np.tile([0.0, 0.0, 1.0], (len(x), 1))
    blended, alone, coarse = line_lookups(gl, method, pos, nrm)
    g = (pos[:, 0] - fine.grid.origin_m[0]) / h  # the lookup's sample point moves along +z only
    hard = np.where((g > lpv_cascade.BAND_START_CELLS)[:, None], alone, coarse)
    level = blended.mean()
    step_blend = np.abs(np.diff(blended, axis=0)).max() / level
    step_hard = np.abs(np.diff(hard, axis=0)).max() / level
    step_fine = np.abs(np.diff(alone[g > 6], axis=0)).max() / level
    print(f"largest step / mean: blended {step_blend:.4f}, hard switch {step_hard:.4f}, "
          f"fine alone inside {step_fine:.4f}")
    # Measured (32 cells): blended 0.0048 (the band spreads the cascades' difference over 4 cells, 80
    # samples), hard switch 0.33, the fine cascade alone inside 0.0024. Bound 0.02.
    assert step_blend < 0.02 < step_hard


def test_cascade_weights_sum_to_one(gl):
    # (c) A uniform field of the same irradiance in both cascades (c = E h^2 per cell: the fine cells hold a
    # quarter of the parent's coefficients) reads E everywhere along a line crossing the band, blended:
    # the weights sum to 1, nothing is counted twice. fp32: 1e-5 relative.
    method, _ = cascaded(gl, 2)
    fine = method.levels[0]
    lobe_down = sh.cosine_lobe_l1(np.array([0.0, 0.0, -1.0])) / np.pi  # light travelling down
    for level in method.levels:
        value = (lobe_down * level.grid.cell_size_m**2).astype(np.float32)
        for c in "rgb":
            gl.write(level.accumulated[f"acc_{c}"], np.broadcast_to(value, tuple(reversed(level.grid.dims)) + (4,)))
    h = fine.grid.cell_size_m
    x = fine.grid.origin_m[0] + h * np.arange(-4.0, 12.0, 0.25)
    pos = np.c_[x, np.full_like(x, 0.3), np.full_like(x, 0.0)]
    nrm = np.tile([0.0, 0.0, 1.0], (len(x), 1))
    saved = method.lookup_vox
    method.lookup_vox = lambda level: None  # plain trilinear: the geometry volume's corners aside
    blended, alone, coarse = line_lookups(gl, method, pos, nrm)
    method.lookup_vox = saved
    e = lobe_down @ sh.cosine_lobe_l1(np.array([0.0, 0.0, -1.0])) / np.pi
    inside = (x > fine.grid.origin_m[0] + h) & (x < fine.grid.origin_m[0] + fine.grid.extent_m[0] - h)
    np.testing.assert_allclose(coarse, e, rtol=1e-5)
    np.testing.assert_allclose(alone[inside], e, rtol=1e-5)
    np.testing.assert_allclose(blended, e, rtol=1e-5)


def test_cascades_leave_a_scene_that_fits_the_fine_grid_unchanged(gl):
    # (b) cell_size_m = 0.25 m: the 2 m corner scene fits one grid of 14 cells <= 16, so cascades = 2 uses one
    # grid, the same as cascades = 1: identical output (exactly, same passes).
    runs = {}
    for c in (1, 2):
        method, result = cascaded(gl, c, grid_cells=16, cell_size_m=0.25, scene=corner_scene())
        assert len(method.levels) == 1 and method.grid.cell_size_m == 0.25
        runs[c] = result.images["indirect"]
    np.testing.assert_array_equal(runs[1], runs[2])


def test_cascades_on_a_scene_larger_than_one_grid(gl):
    # (d) 20 m floor at 32 cells (0.69 m cells) vs cascades = 2 (the finest 0.34 m, around the camera), both
    # against one grid of the finest cell over the whole floor. Finite and non-negative; in the finest
    # cascade's region (weight 1) the cascaded answer agrees with the fine grid better than the single
    # coarse grid. Measured: rel L1 0.302 cascaded against 0.546 on one grid (bias 0.81 against 0.47).
    # At 24 cells (0.95 m) cascades do not help (0.541 against 0.523, bias 1.54), so the test uses 32.
    results = {c: cascaded(gl, c) for c in (1, 2)}
    fine = results[2][0].levels[0]
    ref_method, ref = cascaded(gl, 1, grid_cells=64, cell_size_m=fine.grid.cell_size_m)
    assert ref_method.grid.cell_size_m == fine.grid.cell_size_m
    region, pairs = fine_region_errors(gl, results, ref)
    errors = {c: e[0] for c, e in pairs.items()}
    for c, (_, result) in results.items():
        print(f"cascades {c}: rel L1 vs the fine grid in the fine region ({region.sum()} px) {errors[c]:.3f}, "
              f"bias {pairs[c][1]:.3f}; timings {result.timings_ms}")
    assert region.sum() > 100
    assert errors[2] < 0.7 * errors[1]


# -- octree -------------------------------------------------------------------------------------------
def test_octree_index_merge_equals_numpy(gl):
    # fine := w fine + (1 - w) 1/4 trilinear(coarse), w = clamp(rho / eps - 1, 0, 1) from the colours'
    # summed c0 (lpv_octree_reference.merge). Odd fine dims (the coarse grid's last cells half outside).
    # Light c0 >= 0 as propagated fields hold it, other coefficients signed. fp32: the weight's ratio
    # rounds at 1e-7, so 1e-5 of the largest value.
    rng = np.random.default_rng(13)
    fine = Grid(np.zeros(3), 1.0, (7, 4, 5))
    coarse = lpv_far_field.grid_for(fine)

    def field(grid):
        a = rng.normal(size=tuple(reversed(grid.dims)) + (4,))
        a[..., 0] = rng.uniform(0.0, 1.0, a.shape[:3]) * (rng.random(a.shape[:3]) < 0.8)  # some dark cells
        return a.astype(np.float32)

    fine_acc, coarse_acc = [field(fine) for _ in range(3)], [field(coarse) for _ in range(3)]
    for eps in (1e-6, 0.25):
        acc = {f"acc_{c}": gl.texture(fine.dims, "RGBA32F", a) for c, a in zip("rgb", fine_acc, strict=True)}
        far = {f"acc_{c}": gl.texture(coarse.dims, "RGBA32F", a) for c, a in zip("rgb", coarse_acc, strict=True)}
        lpv_octree.merge(gl, far, coarse, acc, fine, "index", eps)
        want, weights = octree_ref.merge([fine_acc, coarse_acc], eps)
        assert 0.0 < weights[0].mean() < 1.0  # both levels are used
        for c, w in zip("rgb", want, strict=True):
            np.testing.assert_allclose(gl.read(acc[f"acc_{c}"]), w, rtol=0, atol=1e-5 * np.abs(w).max())


def octree_method(gl, merge, levels=3, k=4):
    """An octree LpvMethod on corner_scene at 16 cells without a geometry volume (the transport alone)."""
    method = LpvMethod(gl, GIConfig(method="lpv"), RsmConfig(resolution=32),
                       LpvConfig(grid_cells=16, variant="octree", geometry_volume=False, octree_levels=levels,
                                 octree_iterations=k, octree_merge=merge))
    method.set_scene(corner_scene())
    return method


@pytest.mark.parametrize("merge", ["index", "time"])
def test_octree_work_counts_every_levels_cells_times_steps(gl, merge):
    # work() is the benchmarks' machine-independent cost: sum over levels of cells x steps, exactly the
    # steps lpv_octree.steps gives each level of this 16^3 chain (k = 4, three levels).
    method = octree_method(gl, merge)
    method.run()
    grids = [method.levels[0].grid, *[lv.grid for lv in method.levels[0].octree]]
    span = min(256, sum(grids[-1].dims) - 3)
    want = sum(lpv_octree.steps(i, 4, 3, merge, span) * int(np.prod(g.dims)) for i, g in enumerate(grids))
    assert method.work() == {"propagation_cell_steps": want} and want > 0


@pytest.mark.parametrize("merge", ["index", "time"])
def test_octree_propagation_equals_numpy(gl, merge):
    # The method's own path (fill_octree summing the source down the chain, each level's steps with
    # its shares, the merges) against lpv_octree_reference from one isotropic source and one lobe in
    # the grid. float64 reference against fp32 passes over ~20 steps: 1e-4 of the largest coefficient.
    method = octree_method(gl, merge)
    top = method.levels[0]
    dims = top.grid.dims
    channels = [np.zeros(tuple(reversed(dims)) + (4,), np.float32) for _ in range(3)]
    channels[0][dims[2] // 2, dims[1] // 2, dims[0] // 2, 0] = 1.0
    channels[1][1, 2, 3] = sh.cosine_lobe_l1(np.array([0.6, 0.0, 0.8])) / np.pi
    top.snapshots[0] = volumes(gl, dims, channels)
    method.fill_octree(top, injected=False)
    method.propagate(level=top)
    levels, k = 3, 4
    snapshots = [octree_ref.chain(c, levels) for c in channels]  # per colour, per level
    per_level = list(zip(*snapshots, strict=True))  # per level, per colour
    if merge == "time":
        steps = [lpv_octree.steps(i, k, levels, "time", sum(g.dims) - 3)
                 for i, g in enumerate([top.grid, *[lv.grid for lv in top.octree]])]
        shares = [lambda s, i=i: lpv_octree.time_share(i, s, k, levels) for i in range(levels)]
        accs = [octree_ref.propagate(list(level), [steps[i]] * 3, shares=[shares[i]] * 3)
                for i, level in enumerate(per_level)]
        want = octree_ref.add_up(accs)
    else:
        accs = [octree_ref.propagate(list(level), k) for level in per_level]
        want, _ = octree_ref.merge(accs, method.lpv_config.octree_epsilon)
    for c, w in zip("rgb", want, strict=True):
        np.testing.assert_allclose(gl.read(top.accumulated[f"acc_{c}"]), w, rtol=0, atol=1e-4 * np.abs(w).max())
    assert np.abs(want[0][..., 0]).max() > 0 and np.abs(want[1][..., 0]).max() > 0


def test_octree_time_merge_injects_every_level_itself(gl):
    # The time merge's first bounce: every level gets the VPLs injected itself (a VPL in the coarse cell
    # in front of its surface); each level's injected flux is the same here, where every VPL's point
    # (0.6 of the level's cell in front of its surface) lies inside every level's grid. fp32 sums of
    # ~1000 splats: 1e-5 relative. Levels 3 and 4 (cells of 8 and 16 grid cells) are not blocked.
    method = LpvMethod(gl, GIConfig(method="lpv"), RsmConfig(resolution=32),
                       LpvConfig(grid_cells=16, variant="octree", octree_merge="time", octree_levels=5,
                                 octree_blocked_levels=3))
    method.set_scene(corner_scene())
    method.compute()
    top = method.levels[0]
    fluxes = [flux([gl.read(lv.snapshots[0][f"sh_{c}"]) for c in "rgb"]) for lv in (top, *top.octree)]
    assert len(fluxes) == 5 and fluxes[0].min() > 0
    for f in fluxes[1:]:
        np.testing.assert_allclose(f, fluxes[0], rtol=1e-5)
    assert [lv.blocking is not None for lv in (top, *top.octree)] == [True, True, True, False, False]


def test_octree_epsilon_ramp_pops_less_than_the_non_zero_rule(gl):
    # The spot of corner_scene moves 1 mm per frame for 30 frames; the largest mean |indirect change| /
    # mean between frames. With the paper's non-zero rule (eps 1e-6) a cell switches level as soon as
    # the finer level's first light arrives, a jump in intensity; the ramp (eps 0.5) makes the switch
    # continuous in the light. Measured (index merge, 4 levels, k = 4, 16 cells): 0.080 against 0.028;
    # the rest is VPLs changing cells. The hard case's room (tests/hard/test_temporal.py, 60 frames,
    # defaults otherwise): 0.116 against 0.023, the time merge 0.014, the far field 0.011.
    from dataclasses import replace

    worst = {}
    for eps in (1e-6, 0.5):
        method = LpvMethod(gl, GIConfig(method="lpv"), RsmConfig(resolution=64),
                           LpvConfig(grid_cells=16, variant="octree", octree_merge="index", octree_levels=4,
                                     octree_iterations=4, octree_epsilon=eps))
        scene = corner_scene()
        method.set_scene(scene)
        light, prev, worst[eps] = scene.lights[0], None, 0.0
        for frame in range(30):
            scene.lights[0] = replace(light, position_m=light.position_m + np.array([1e-3 * frame, 0.0, 0.0]))
            image = method.run().images["indirect"][..., :3]
            if prev is not None:
                worst[eps] = max(worst[eps], float(np.abs(image - prev).mean() / prev.mean()))
            prev = image
    print(f"octree popping, largest frame change: non-zero rule {worst[1e-6]:.3f}, ramp {worst[0.5]:.3f}")
    assert worst[1e-6] > 0.05  # the switch pops: the test measures something
    assert worst[0.5] < 0.5 * worst[1e-6]
