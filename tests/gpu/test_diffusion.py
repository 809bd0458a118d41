"""The `diffusion` passes (cells, inject, emit, propagate, add, far field, lookup) against their numpy twin,
addon/engine/diffusion_reference.py, whose own closed-form checks are tests/unit/test_diffusion_reference.py.

The GPU computes in fp32 what the twin computes in float64: sums of a few dozen products of numbers of
order 1, so 1e-5 relative to the largest value compared is several times the rounding seen and far
below any error of the equations (a wrong face, side or weight changes values by > 1e-2 relative).
Volumes read back as (z, y, x, 4) arrays.
"""

import numpy as np
import pytest

from addon.engine import cone_fields, sh
from addon.engine import diffusion_reference as ref
from addon.engine.grid import Grid
from addon.engine.passes import atlas as atlas_pass
from addon.engine.passes import (
    diffusion_cells,
    diffusion_far_field,
    diffusion_inject,
    diffusion_lookup,
    diffusion_propagate,
)

pytestmark = pytest.mark.gpu

GRID = Grid(np.array([-1.0, 0.5, 0.0]), 0.5, (6, 5, 4))
RTOL = 1e-5


def zyx(grid, channels=4):
    return (*reversed(grid.dims), channels)


def random_voxels(rng, grid, share=0.35):
    """Voxelizer-like volumes (z, y, x, 4): occupancy in albedo's alpha, unit or cancelled mean normals,
    projected areas up to 1.5 cells^2 (more than a cell's cross-section: the clamp to 1 is exercised)."""
    occ = rng.random(zyx(grid, 0)[:3]) < share
    albedo = np.zeros(zyx(grid), np.float32)
    albedo[..., :3] = rng.uniform(0.1, 0.9, zyx(grid, 3))
    albedo[..., 3] = occ
    normal = rng.normal(size=zyx(grid, 3))
    normal /= np.linalg.norm(normal, axis=-1, keepdims=True)
    normal[rng.random(occ.shape) < 0.25] = 0.0
    proj = rng.uniform(0.0, 1.5, zyx(grid, 3))
    normal[~occ] = 0.0
    proj[~occ] = 0.0
    albedo[~occ] = 0.0
    pad = np.zeros((*occ.shape, 1))
    return {"vox_albedo": albedo, "vox_normal": np.concatenate([normal, pad + 1.0], -1).astype(np.float32),
            "vox_projected": np.concatenate([proj, pad], -1).astype(np.float32)}


def gpu_cells(gl, voxels, grid=GRID):
    textures = {k: gl.texture(grid.dims, "RGBA32F", v) for k, v in voxels.items()}
    cells = diffusion_cells.textures(gl, grid)
    diffusion_cells.run(gl, textures, cells, grid)
    return textures, cells


def ref_cells(voxels):
    return ref.cells(voxels["vox_albedo"][..., 3] > 0, voxels["vox_normal"], voxels["vox_projected"])


def open_mask(cell):
    """The twin's open faces (bits 0-5) and receiving sides (bit 6 plus, 7 minus) as cells.comp.glsl packs them."""
    return np.sum(cell["open"] * (1 << np.arange(6)), axis=-1) + 64 * cell["receives"][..., 0] \
        + 128 * cell["receives"][..., 1]


def test_cells_are_the_twins(gl):
    rng = np.random.default_rng(1)
    voxels = random_voxels(rng, GRID)
    _, cells = gpu_cells(gl, voxels)
    want = ref_cells(voxels)
    normal, block = gl.read(cells["cell_normal"]), gl.read(cells["cell_block"])
    assert want["occupied"].any() and (~want["occupied"]).any()
    np.testing.assert_allclose(normal[..., :3], want["normal"], rtol=0, atol=1e-6)
    np.testing.assert_allclose(normal[..., 3], want["area"], rtol=0, atol=1e-6)
    np.testing.assert_allclose(block[..., :3], want["block"], rtol=0, atol=1e-7)
    # w: 0 empty, else 1 + the mask, exactly (small integers in fp32).
    np.testing.assert_array_equal(block[..., 3], np.where(want["occupied"], 1 + open_mask(want), 0))


def random_fields(rng, grid, emitters=10):
    """Per channel, cells holding sums of clamped-cosine lobes (realizable, as the method's fields are)
    plus some cone-shaped carried light."""
    out = []
    for _ in range(3):
        v = np.zeros(zyx(grid))
        for _ in range(emitters):
            z, y, x = (rng.integers(0, n) for n in zyx(grid, 0)[:3])
            n = rng.normal(size=3)
            v[z, y, x] += rng.uniform(0.1, 2.0) * sh.cosine_lobe_l1(n / np.linalg.norm(n)) / np.pi
            v[z, y, x] += rng.uniform(0.0, 1.0) * ref.CONES[rng.integers(6)]
        out.append(v.astype(np.float32))
    return out


def sh_volumes(gl, grid, data=None):
    d = data or [None] * 3
    return {f"sh_{c}": gl.texture(grid.dims, "RGBA32F", x) for c, x in zip("rgb", d, strict=True)}


@pytest.mark.parametrize("transfer, cone", [(t, None) for t in ref.TRANSFERS] + [("directional", b) for b in (0, 3, 4)])
def test_propagation_steps_are_the_twins(gl, transfer, cone):
    # Two steps through random cells: the next fields, and the absorbed flux written by the first step
    # and added by the second (stale contents in the accumulation are overwritten by the first). With a
    # cone, that cone field's (cone_fields.step): its matrices compiled into the step, the clamp, the
    # open faces and the residual as directional's.
    rng = np.random.default_rng(2)
    voxels = random_voxels(rng, GRID)
    _, cells = gpu_cells(gl, voxels)
    fields = random_fields(rng, GRID) if cone is None else random_cone_fields(rng, GRID, cone)
    sets = [sh_volumes(gl, GRID, fields), sh_volumes(gl, GRID)]
    stale = np.full(zyx(GRID), 5.0, np.float32)
    absorbed = {k: gl.texture(GRID.dims, "RGBA32F", stale) for k in ("flux_plus", "flux_minus")}
    cell = ref_cells(voxels)
    want = [np.asarray(f, np.float64) for f in fields]
    plus, minus = np.zeros((3, *zyx(GRID, 0)[:3])), np.zeros((3, *zyx(GRID, 0)[:3]))
    for i in range(2):
        diffusion_propagate.run(gl, sets[i % 2], sets[(i + 1) % 2], absorbed, cells, GRID, first_step=i == 0,
                                transfer=transfer, cone=cone)
        for ch in range(3):
            want[ch], p, m = ref.step(want[ch], cell, transfer) if cone is None else \
                cone_fields.step(want[ch], cell, cone)
            plus[ch] += p
            minus[ch] += m
        got = [gl.read(sets[(i + 1) % 2][f"sh_{c}"]) for c in "rgb"]
        for ch in range(3):
            np.testing.assert_allclose(got[ch], want[ch], rtol=0, atol=RTOL * np.abs(want[ch]).max())
    got_plus, got_minus = gl.read(absorbed["flux_plus"]), gl.read(absorbed["flux_minus"])
    assert plus.sum() > 0 and minus.sum() > 0  # both sides are exercised
    for ch in range(3):
        np.testing.assert_allclose(got_plus[..., ch], plus[ch], rtol=0, atol=RTOL * plus.max())
        np.testing.assert_allclose(got_minus[..., ch], minus[ch], rtol=0, atol=RTOL * minus.max())


def atlas_of(gl, atlas, grid, volume):
    """The injection atlas (layer z as tile z) holding a (z, y, x, 4) volume."""
    a = np.zeros((atlas.size[1], atlas.size[0], 4), np.float32)
    nx, ny, _ = grid.dims
    for z in range(grid.dims[2]):
        tx, ty = z % atlas.tiles_x, z // atlas.tiles_x
        a[ty * ny:(ty + 1) * ny, tx * nx:(tx + 1) * nx] = volume[z]
    return gl.texture(atlas.size, "RGBA32F", a)


@pytest.mark.parametrize("emitter_class, cone", [(ref.EVERY_CLASS, None), (0, None), (5, None),
                                                  (ref.EVERY_CLASS, 0), (ref.EVERY_CLASS, 5), (4, 2)])
def test_emitters_are_the_twins(gl, emitter_class, cone):
    # From the injection atlas (no albedo: the VPLs' flux is reflected light already) and from absorbed
    # flux volumes times the voxels' albedo; empty cells emit isotropically; every cell is written. One
    # emitter class's emitters: the sides of that class alone, and 1/5 of an empty cell's light.
    # A cone field's (cone_fields.emit): each lobe's part in the cone by the same 8 x 8 points per cube
    # face, an empty cell's light times the cone's isotropic part. That part is gram^-1 times the lobe's
    # projection, and a cone's Gram matrix has condition number 319 (the L1 basis is nearly dependent
    # over a sixth of the sphere): fp32's rounding of the projection (1e-7 relative) grows to 3e-5 at
    # most, so 1e-4 there.
    tolerance = RTOL if cone is None else 1e-4
    rng = np.random.default_rng(3)
    voxels = random_voxels(rng, GRID)
    textures, cells = gpu_cells(gl, voxels)
    cell = ref_cells(voxels)
    fp, fm = (rng.uniform(0.0, 2.0, zyx(GRID)).astype(np.float32) for _ in range(2))
    atlas, injected, _ = diffusion_inject.atlas_target(gl, GRID)
    assert atlas.tiles_x == 2  # 4 layers as 2 x 2 tiles: the tiling is exercised
    tiles = {"flux_plus": atlas_of(gl, atlas, GRID, fp), "flux_minus": atlas_of(gl, atlas, GRID, fm)}
    volumes = {"flux_plus": gl.texture(GRID.dims, "RGBA32F", fp), "flux_minus": gl.texture(GRID.dims, "RGBA32F", fm)}
    for source, albedo in ((tiles, None), (volumes, voxels["vox_albedo"])):
        out = sh_volumes(gl, GRID, [np.full(zyx(GRID), 9.0, np.float32)] * 3)
        if albedo is None:
            diffusion_inject.emit(gl, source, cells, out, GRID, atlas=atlas, emitter_class=emitter_class, cone=cone)
        else:
            diffusion_inject.emit(gl, source, cells, out, GRID, vox_albedo=textures["vox_albedo"],
                                  emitter_class=emitter_class, cone=cone)
        for ch, c in enumerate("rgb"):
            a = 1.0 if albedo is None else albedo[..., ch]
            args = (fp[..., ch], fm[..., ch], cell["normal"], cell["occupied"])
            want = (ref.emit(*args, a, emitter_class) if cone is None
                    else cone_fields.emit(*args, cone, a, emitter_class))
            np.testing.assert_allclose(gl.read(out[f"sh_{c}"]), want, rtol=0, atol=tolerance * np.abs(want).max())


def test_injection_is_the_twins(gl):
    # 60 VPLs over a grid whose cells are half occupied: each in its cell or half a cell behind it, on
    # the side of the plane its normal faces; VPLs outside the grid and empty texels add nothing.
    rng = np.random.default_rng(4)
    voxels = random_voxels(rng, GRID, share=0.5)
    _, cells = gpu_cells(gl, voxels)
    cell = ref_cells(voxels)
    res, count = 8, 60
    n = rng.normal(size=(count, 3))
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    p = GRID.origin_m + rng.uniform(-0.05, 1.05, size=(count, 3)) * GRID.extent_m
    f = rng.uniform(0.1, 2.0, size=(count, 3))
    pos, nrm, phi = (np.zeros((res, res, 4), np.float32) for _ in range(3))
    texels = rng.choice(res * res, count, replace=False)
    for k, t in enumerate(texels):
        pos.reshape(-1, 4)[t] = [*p[k], 1.0]
        nrm.reshape(-1, 4)[t] = [*n[k], 0.01]
        phi.reshape(-1, 4)[t, :3] = f[k]
    rsm = {k: gl.texture((res, res), "RGBA32F", a) for k, a in (("position", pos), ("normal", nrm), ("flux", phi))}
    atlas, injected, target = diffusion_inject.atlas_target(gl, GRID)
    gl.clear(target)
    diffusion_inject.run(gl, target, atlas_pass.texel_points(gl, res, diffusion_inject.SPEC), rsm, GRID, atlas,
                         cells["cell_normal"])
    # Read through emit's atlas path into volumes: the same per-cell sums, then compare the lobes' flux
    # per side via the twin's emitters.
    out = sh_volumes(gl, GRID)
    diffusion_inject.emit(gl, injected, cells, out, GRID, atlas=atlas)
    p32, n32 = pos.reshape(-1, 4)[texels, :3].astype(np.float64), nrm.reshape(-1, 4)[texels, :3].astype(np.float64)
    for ch, c in enumerate("rgb"):
        plus, minus = ref.inject(GRID, p32, n32, f[:, ch], cell)
        want = ref.emit(plus, minus, cell["normal"], cell["occupied"])
        np.testing.assert_allclose(gl.read(out[f"sh_{c}"]), want, rtol=0, atol=RTOL * np.abs(want).max())
    # Both rules ran: some VPLs in an occupied cell of their own, some moved half a cell behind.
    cell_of = np.floor((p32 - GRID.origin_m) / GRID.cell_size_m).astype(int)
    behind = np.floor((p32 - 0.5 * GRID.cell_size_m * n32 - GRID.origin_m) / GRID.cell_size_m).astype(int)
    dims = np.array(GRID.dims)

    def occupied(c):
        inside = np.all((c >= 0) & (c < dims), axis=1)
        c = np.clip(c, 0, dims - 1)
        return inside & cell["occupied"][c[:, 2], c[:, 1], c[:, 0]]

    assert occupied(cell_of).any() and (~occupied(cell_of) & occupied(behind)).any()


def test_add_sums_bounces(gl):
    rng = np.random.default_rng(5)
    a, b = (rng.random(zyx(GRID)).astype(np.float32) for _ in range(2))
    _, cells = gpu_cells(gl, random_voxels(rng, GRID))
    bounce = {k: gl.texture(GRID.dims, "RGBA32F", a) for k in ("flux_plus", "flux_minus")}
    total = {k: gl.texture(GRID.dims, "RGBA32F", b) for k in ("flux_plus", "flux_minus")}
    diffusion_propagate.add(gl, bounce, total, GRID, first=True, cell_normal=cells["cell_normal"])
    np.testing.assert_array_equal(gl.read(total["flux_plus"]), a)
    diffusion_propagate.add(gl, bounce, total, GRID, first=False, cell_normal=cells["cell_normal"])
    np.testing.assert_allclose(gl.read(total["flux_minus"]), 2 * a, rtol=1e-7)


@pytest.mark.parametrize("skip_class", [0, 3])
def test_add_skips_the_sides_of_the_propagated_class(gl, skip_class):
    # One emitter class's propagation reaches every side but those of its own class (the dominant signed
    # axis of the side's normal: the plus side's n, the minus side's -n): those keep their total, and
    # with first=True start from 0.
    rng = np.random.default_rng(6)
    voxels = random_voxels(rng, GRID, share=1.0)
    _, cells = gpu_cells(gl, voxels)
    normal = gl.read(cells["cell_normal"])[..., :3]
    a, b = (rng.random(zyx(GRID)).astype(np.float32) for _ in range(2))
    bounce = {k: gl.texture(GRID.dims, "RGBA32F", a) for k in ("flux_plus", "flux_minus")}
    for first in (True, False):
        total = {k: gl.texture(GRID.dims, "RGBA32F", b) for k in ("flux_plus", "flux_minus")}
        diffusion_propagate.add(gl, bounce, total, GRID, first=first, cell_normal=cells["cell_normal"],
                                skip_class=skip_class)
        for side, n in (("flux_plus", normal), ("flux_minus", -normal)):
            skipped = (ref.emitter_class(n) == skip_class)[..., None]
            assert skipped.any() and not skipped.all()
            kept = 0.0 if first else b
            np.testing.assert_allclose(gl.read(total[side]), np.where(skipped, kept, kept + a), rtol=1e-7)


def faces_of(volumes):
    """(z, y, x, 6, 3) from the five packed volumes of flux per face (diffusion/faces.glsl: number 3 f +
    channel at volume (3 f + channel) // 4, component (3 f + channel) % 4)."""
    flat = np.concatenate([volumes[i] for i in range(5)], axis=-1)  # (z, y, x, 20)
    return flat[..., :18].reshape(*flat.shape[:3], 6, 3)


def test_propagation_by_face_is_the_twins(gl):
    # The far grid's steps: the same next fields, the absorbed flux kept by the face it came through
    # (written by the first step, added by the second).
    rng = np.random.default_rng(10)
    voxels = random_voxels(rng, GRID, share=0.5)
    _, cells = gpu_cells(gl, voxels)
    fields = random_fields(rng, GRID)
    sets = [sh_volumes(gl, GRID, fields), sh_volumes(gl, GRID)]
    absorbed = diffusion_propagate.faces(gl, GRID)
    cell = ref_cells(voxels)
    want = [np.asarray(f, np.float64) for f in fields]
    faces = np.zeros((3, *zyx(GRID, 0)[:3], 6))
    for i in range(2):
        diffusion_propagate.run(gl, sets[i % 2], sets[(i + 1) % 2], absorbed, cells, GRID, first_step=i == 0,
                                transfer="directional")
        for ch in range(3):
            want[ch], a = ref.step_by_face(want[ch], cell, "directional")
            faces[ch] += a
    for ch, c in enumerate("rgb"):
        got = gl.read(sets[0][f"sh_{c}"])
        np.testing.assert_allclose(got, want[ch], rtol=0, atol=RTOL * np.abs(want[ch]).max())
    got = faces_of([gl.read(absorbed[f"acc_{i}"]) for i in range(5)])
    assert (faces > 0).sum(axis=(0, 1, 2, 3)).min() > 0  # light came through every face
    for ch in range(3):
        np.testing.assert_allclose(got[..., ch], faces[ch], rtol=0, atol=RTOL * faces.max())


def far_cells_pair(gl, rng, shift):
    """Random fine cells on GRID (6 x 5 x 4) and independent random cells on its far grid starting `shift`
    fine cells before it (odd sides leave far layers half covered), dense enough that far cells share
    light through some faces and not others."""
    far = diffusion_far_field.grid_for(GRID, shift)
    voxels, far_voxels = random_voxels(rng, GRID, share=0.6), random_voxels(rng, far.grid, share=0.5)
    _, cells = gpu_cells(gl, voxels)
    _, far_cells = gpu_cells(gl, far_voxels, far.grid)
    return far, cells, far_cells, ref_cells(voxels), ref_cells(far_voxels)


@pytest.mark.parametrize("shift", [(0, 0, 0), (1, 0, 1)])
def test_far_field_weights_and_add_are_the_twins(gl, shift):
    # The far grid's absorbed flux per face shared onto the fine sides light can reach, by their block
    # on the face's axis and the trilinear tents of the far cells around them, added to what the fine
    # grid absorbed itself; every far cell that shares gives out exactly its flux.
    rng = np.random.default_rng(12)
    far, cells, far_cells, cell, far_cell = far_cells_pair(gl, rng, shift)
    far_grid = far.grid
    weights = diffusion_far_field.weights(gl, far_cells, far, cells, GRID)
    got_weights = np.concatenate([gl.read(weights["weight_0"]), gl.read(weights["weight_1"])[..., :2]], -1)
    want_weights = ref.far_weights(far_cell, cell, shift)
    assert (want_weights > 0).any() and (want_weights == 0).any()
    np.testing.assert_allclose(got_weights, want_weights, rtol=0, atol=RTOL * want_weights.max())
    far_faces = rng.uniform(0.0, 2.0, (*zyx(far_grid, 0)[:3], 6, 3))
    flat = np.zeros((*zyx(far_grid, 0)[:3], 20), np.float32)
    flat[..., :18] = far_faces.reshape(*far_faces.shape[:3], 18)
    far_absorbed = {f"acc_{i}": gl.texture(far_grid.dims, "RGBA32F", np.ascontiguousarray(flat[..., 4 * i:4 * i + 4]))
                    for i in range(5)}
    own = rng.uniform(0.0, 1.0, zyx(GRID)).astype(np.float32)
    absorbed = {k: gl.texture(GRID.dims, "RGBA32F", own) for k in ("flux_plus", "flux_minus")}
    diffusion_far_field.add(gl, far_absorbed, weights, far, absorbed, cells, GRID)
    got_plus, got_minus = gl.read(absorbed["flux_plus"]), gl.read(absorbed["flux_minus"])
    for ch in range(3):
        plus, minus = ref.far_add(far_faces[..., ch], want_weights, cell, shift)
        assert plus.max() > 0 and minus.max() > 0
        np.testing.assert_allclose(got_plus[..., ch] - own[..., ch], plus, rtol=0, atol=RTOL * plus.max())
        np.testing.assert_allclose(got_minus[..., ch] - own[..., ch], minus, rtol=0, atol=RTOL * minus.max())
        shared = np.sum(np.where(want_weights > 0, far_faces[..., ch], 0.0))
        np.testing.assert_allclose(plus.sum() + minus.sum(), shared, rtol=1e-12)


@pytest.mark.parametrize("cone", [None, 2])
def test_far_field_hand_over_frees_enclosed_cells(gl, cone):
    # The fine light in flight summed per far cell, the light of cells with no open face moved to the face
    # and edge neighbours that have one, mostly along the light's direction (a cone field's: its cone's
    # axis); no light made or lost.
    # A far grid of 5 x 5 x 5 starting a fine cell before the fine grid on y (faces out of the grid count
    # as open, so a small grid has no enclosed cell), 85 % occupied: enclosed cells with and without a
    # neighbour to take their light.
    rng = np.random.default_rng(13)
    fine = Grid(np.zeros(3), 0.5, (10, 9, 10))
    far = diffusion_far_field.grid_for(fine, (0, 1, 0))
    far_grid = far.grid
    assert far_grid.dims == (5, 5, 5)
    far_voxels = random_voxels(rng, far_grid, share=0.85)
    _, far_cells = gpu_cells(gl, far_voxels, far_grid)
    far_cell = ref_cells(far_voxels)
    enclosed = far_cell["occupied"] & ~far_cell["open"].any(-1)
    assert enclosed.sum() > 5 and (~enclosed).any()
    fields = random_fields(rng, fine, emitters=200)
    snapshots = [sh_volumes(gl, far_grid), sh_volumes(gl, far_grid)]
    diffusion_far_field.hand_over(gl, sh_volumes(gl, fine, fields), fine, snapshots, far_cells, far, cone)
    summed = np.stack([ref._coarse_sum_field(np.asarray(f, np.float64), zyx(far_grid, 0)[:3], far.shift)
                       for f in fields])
    want = ref.far_move_enclosed(summed, far_cell, cone)
    assert not np.allclose(want, summed)  # some light moved
    for ch, c in enumerate("rgb"):
        np.testing.assert_allclose(gl.read(snapshots[0][f"sh_{c}"]), want[ch], rtol=0,
                                   atol=RTOL * np.abs(want[ch]).max())
    np.testing.assert_allclose(want[..., 0].sum(), summed[..., 0].sum(), rtol=1e-12)


def test_lookup_is_the_twins(gl):
    # Points spread over the grid (some near no occupied cell: the 0 fallback; some whose normals are
    # perpendicular to every neighbour's plane: the trilinear fallback) with random normals.
    rng = np.random.default_rng(6)
    voxels = random_voxels(rng, GRID, share=0.3)
    _, cells = gpu_cells(gl, voxels)
    cell = ref_cells(voxels)
    fp, fm = (rng.uniform(0.0, 2.0, zyx(GRID)).astype(np.float32) for _ in range(2))
    total = {"flux_plus": gl.texture(GRID.dims, "RGBA32F", fp), "flux_minus": gl.texture(GRID.dims, "RGBA32F", fm)}
    w, h = 16, 8
    pts = GRID.origin_m + rng.uniform(0.0, 1.0, size=(h * w, 3)) * GRID.extent_m
    nrm = rng.normal(size=(h * w, 3))
    nrm /= np.linalg.norm(nrm, axis=1, keepdims=True)
    pos = np.concatenate([pts, np.ones((h * w, 1))], 1).reshape(h, w, 4).astype(np.float32)
    pos[0, :3, 3] = 0.0  # no geometry: written 0
    gbuf = {"position": gl.texture((w, h), "RGBA32F", pos),
            "normal": gl.texture((w, h), "RGBA32F", np.concatenate([nrm, np.zeros((h * w, 1))], 1)
                                 .reshape(h, w, 4).astype(np.float32))}
    indirect = gl.texture((w, h), "RGBA32F", np.full((h, w, 4), 3.0, np.float32))
    diffusion_lookup.run(gl, gbuf, cells, total, indirect, GRID)
    got = gl.read(indirect).reshape(-1, 4)
    g = (pos.reshape(-1, 4)[:, :3].astype(np.float64) - GRID.origin_m) / GRID.cell_size_m
    n64 = nrm.astype(np.float32).astype(np.float64)
    for ch in range(3):
        want = ref.lookup(g, n64, cell, fp[..., ch], fm[..., ch], GRID.cell_size_m ** 2)
        want[:3] = 0.0
        np.testing.assert_allclose(got[:, ch], want, rtol=0, atol=RTOL * want.max())
    assert (got[3:, 0] == 0).any() and (got[3:, 0] > 0).any()  # both the fallback and the lookup ran


def random_cone_fields(rng, grid, cone, emitters=10):
    """Per channel, cone `cone`'s fields of Lambertian emitters and isotropic light in random cells
    (cone_fields.emit's, as the method's are)."""
    out = []
    for _ in range(3):
        fp, fm = np.zeros(zyx(grid, 0)[:3]), np.zeros(zyx(grid, 0)[:3])
        for _ in range(emitters):
            z, y, x = (rng.integers(0, n) for n in zyx(grid, 0)[:3])
            fp[z, y, x] += rng.uniform(0.1, 2.0)
            fm[z, y, x] += rng.uniform(0.0, 0.5)
        normal = rng.normal(size=zyx(grid, 3))
        normal /= np.linalg.norm(normal, axis=-1, keepdims=True)
        occupied = rng.random(fp.shape) < 0.7
        out.append(cone_fields.emit(fp, fm, normal, occupied, cone).astype(np.float32))
    return out
