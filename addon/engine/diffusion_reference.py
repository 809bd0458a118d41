"""numpy twin of the `diffusion` transport (Mavridis et al., seeds 000): cells, emitters, one gather step,
re-emission, reconstruction.

The one numpy reference of the method: tests/unit/test_diffusion_reference.py checks it against closed
forms, tests/gpu/test_diffusion.py checks the GPU passes against it. It mirrors
- passes/diffusion_cells.py (gpu_shaders/diffusion/cells.comp.glsl): `cells`;
- passes/diffusion_propagate.py (diffusion/emit.comp.glsl, diffusion/propagate.comp.glsl): `emit`,
  `face_fluxes`, `step`;
- passes/diffusion_far_field.py (diffusion/far_field_move, far_field_weights, far_field_add.comp.glsl):
  `far_move_enclosed`, `far_weights`, `far_add`;
- passes/diffusion_lookup.py (diffusion/lookup.comp.glsl): `lookup`.
docs/DIFFUSION.md derives the equations. float64 here, fp32 on the GPU.

Conventions (as lpv_reference): one colour channel at a time; a field is an array (z, y, x, 4) of the L1
SH (order 1, y, z, x) of the radiant intensity, W/sr, of the light in a cell by direction of travel; its
flux is 2 sqrt(pi) c0 (W). Directions d are listed in AXES (+x -x +y -y +z -z). A cell's surface is a
two-sided plane with unit normal n (the `plus` side is the one n points to); flux absorbed on each side
is in W, areas in cells^2 (x h^2 for m^2).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from . import sh
from .lpv_reference import gpu_improved_transfer
from .passes import lpv_inject
from .passes.diffusion_propagate import flux_cross
from .passes.lpv_propagate import improved_constants

AXES = ((0, 1.0), (0, -1.0), (1, 1.0), (1, -1.0), (2, 1.0), (2, -1.0))
DIRECTIONS = np.array([np.eye(3)[axis] * sign for axis, sign in AXES])  # (6, 3)
FLUX_PER_C0 = 2.0 * np.sqrt(np.pi)  # W per unit of c0
FACE_SOLID_ANGLE_SR = 2.0 * np.pi / 3.0  # a face of a cube seen from its centre: 4 pi / 6
# The paper's transfer L_j = T_d <L_i, T_d> normalised (DIGESTS.md, 000): the flux <L_i, T_d> through a
# face leaves the receiving cell as a uniform intensity over that face's cone, flux / (2 pi / 3) W/sr.
TRANSFER_NORM = 1.0 / FACE_SOLID_ANGLE_SR  # 3 / (2 pi)
# L1 projection of the face cone's indicator T_d: c0 = Y00 x 2 pi / 3 = sqrt(pi) / 3; band 1 = Y1 x the
# cone's projected solid angle, the integral of w.d over it, 2 sqrt(2) atan(1 / sqrt(2)) (a unit square
# seen from half a unit: form factor 0.554 x pi).
CONE_C0 = sh.Y00 * FACE_SOLID_ANGLE_SR
CONE_C1 = sh.Y1 * 2.0 * np.sqrt(2.0) * np.arctan(1.0 / np.sqrt(2.0))
_SLOT = (3, 1, 2)  # the coefficient index of axis x, y, z in (1, y, z, x)
SIDE_EPSILON = 1e-3  # |d.n| below this: a face parallel to the surface feeds both sides half and half
LOOKUP_WEIGHT_FLOOR = 1e-3  # added to every trilinear weight of the lookup (`lookup`)


def cone(d: np.ndarray) -> np.ndarray:
    """T_d in L1 SH for a unit direction (..., 3)."""
    d = np.asarray(d, np.float64)
    return np.concatenate([np.full((*d.shape[:-1], 1), CONE_C0), CONE_C1 * d[..., [1, 2, 0]]], axis=-1)


CONES = cone(DIRECTIONS)  # (6, 4)


def flux_w(field: np.ndarray) -> float:
    return FLUX_PER_C0 * float(np.sum(field[..., 0], dtype=np.float64))


# -- cells ---------------------------------------------------------------------------------------------
def cells(occupied: np.ndarray, vox_normal: np.ndarray, vox_projected: np.ndarray) -> dict[str, np.ndarray]:
    """What the transport needs of the voxels, per cell (arrays (z, y, x, ...)):
    - `normal` (3): the surface's plane, unit: the voxels' mean normal, or where it cancels (both faces of
      a thin wall in one cell) the axis along which the surfaces project the most; 0 in empty cells;
    - `block` (3): per axis the share of a face's inflow the surface absorbs, min(1, projected area);
    - `open` (6, bool): the faces light may leave through: every face of an empty cell, and of an
      occupied one those to empty cells or out of the grid (a surface's light goes into open space: two
      coplanar cells of a floor do not light each other);
    - `receives` (2, bool): whether light can reach the plus / minus side at all: some face on that side
      (d . n > 0 for plus, < 0 for minus) leads to an empty cell in the grid; the cell where a floor
      meets a wall touches no empty cell on its room side, so nothing arrives there and the lookup
      must not read its 0 as the light of that side;
    - `area` (cells^2): each side's receiving area, sum over axes of block x (1 where the normal has a
      component along the axis, else 1/2): the flux a uniform radiance L puts on a side is pi L x area
      x h^2, so the lookup's flux / area is exact in a uniform field whatever the cell holds.
    occupied (z, y, x) bool; vox_normal (z, y, x, 3 or 4): unit or 0; vox_projected (z, y, x, 3 or 4)."""
    occ = np.asarray(occupied, bool)
    mean = np.asarray(vox_normal, np.float64)[..., :3]
    proj = np.asarray(vox_projected, np.float64)[..., :3]
    has_mean = np.linalg.norm(mean, axis=-1, keepdims=True) > 0.5
    major = np.eye(3)[np.argmax(proj, axis=-1)]
    normal = np.where(occ[..., None], np.where(has_mean, mean, major), 0.0)
    block = np.where(occ[..., None], np.minimum(1.0, proj), 0.0)
    share = np.where(np.abs(normal) > SIDE_EPSILON, 1.0, 0.5)
    area = np.sum(block * share, axis=-1)
    open_faces = np.ones((*occ.shape, 6), bool)
    padded = np.pad(occ, 1)
    for f, (axis, sign) in enumerate(AXES):
        shift = [slice(1, -1)] * 3
        zyx = 2 - axis
        shift[zyx] = slice(1 + int(sign), padded.shape[zyx] - 1 + int(sign))
        open_faces[..., f] = ~occ | ~padded[tuple(shift)]
    inside = np.pad(np.ones(occ.shape, bool), 1)
    receives = np.zeros((*occ.shape, 2), bool)
    for axis, sign in AXES:
        shift = [slice(1, -1)] * 3
        zyx = 2 - axis
        shift[zyx] = slice(1 + int(sign), padded.shape[zyx] - 1 + int(sign))
        source = inside[tuple(shift)] & ~padded[tuple(shift)]  # an empty cell in the grid
        dn = normal[..., axis] * sign
        receives[..., 0] |= source & (dn > SIDE_EPSILON)
        receives[..., 1] |= source & (dn < -SIDE_EPSILON)
    receives &= occ[..., None]
    return {"normal": normal, "block": block, "open": open_faces, "area": area, "occupied": occ,
            "receives": receives}


# -- emitters ------------------------------------------------------------------------------------------
def inject(grid, positions_m: np.ndarray, normals: np.ndarray, flux_w: np.ndarray, cell: dict):
    """(flux on the plus side, on the minus side) per cell (z, y, x) from VPLs (n, 3) m, unit normals,
    flux (n,) W: each in the cell holding it, or half a cell behind it (-0.5 h n) when that one is
    occupied and its own is not, on the side of the cell's plane its normal faces (plus on ties and in
    empty cells); VPLs outside the grid are dropped."""
    occ = cell["occupied"]
    dims = np.array(grid.dims)
    g = (np.asarray(positions_m, np.float64) - grid.origin_m) / grid.cell_size_m
    plus = np.zeros(occ.shape)
    minus = np.zeros(occ.shape)

    def occupied_at(c):
        inside = np.all((c >= 0) & (c < dims), axis=1)
        cc = np.clip(c, 0, dims - 1)
        return inside & occ[cc[:, 2], cc[:, 1], cc[:, 0]], inside

    c = np.floor(g).astype(int)
    here, inside = occupied_at(c)
    behind = np.floor(g - 0.5 * np.asarray(normals)).astype(int)
    there, inside_behind = occupied_at(behind)
    use_behind = ~here & there
    c = np.where(use_behind[:, None], behind, c)
    inside = np.where(use_behind, inside_behind, inside)
    cc = np.clip(c, 0, dims - 1)
    n_cell = cell["normal"][cc[:, 2], cc[:, 1], cc[:, 0]]
    on_plus = np.sum(normals * n_cell, axis=1) >= 0.0
    for side, sel in ((plus, inside & on_plus), (minus, inside & ~on_plus)):
        np.add.at(side, (c[sel, 2], c[sel, 1], c[sel, 0]), np.asarray(flux_w)[sel])
    return plus, minus


EVERY_CLASS = -1  # emit / add: every side, no emitter class singled out


def emitter_class(normal: np.ndarray) -> np.ndarray:
    """The emitter class of sides with these normals (..., 3): lpv's (the dominant signed axis, numbered
    as AXES)."""
    return lpv_inject.emitter_class(np.asarray(normal))


def emit(flux_plus: np.ndarray, flux_minus: np.ndarray, normal: np.ndarray, occupied: np.ndarray,
         albedo: np.ndarray | float = 1.0, emitter_class_only: int = EVERY_CLASS) -> np.ndarray:
    """The field of Lambertian emitters (z, y, x, 4): each side of a cell's plane reflects albedo x its
    flux (W) as a clamped-cosine lobe about its normal, albedo x flux / pi x cosine_lobe(+-n) (flux
    exactly albedo x flux); an empty cell (a VPL whose surface fell in no occupied cell) emits it
    isotropically. With `emitter_class_only` (0..5), one emitter class's propagation: only the sides of
    that class emit, and an empty cell 1/5 of its light (a side takes in five classes' light, all but
    its own, so it receives all of an empty cell's)."""
    fp = np.asarray(flux_plus, np.float64) * albedo
    fm = np.asarray(flux_minus, np.float64) * albedo
    share = 1.0
    if emitter_class_only != EVERY_CLASS:
        fp = fp * (emitter_class(normal) == emitter_class_only)
        fm = fm * (emitter_class(-np.asarray(normal)) == emitter_class_only)
        share = 0.2
    lobes = (fp[..., None] * sh.cosine_lobe_l1(normal) + fm[..., None] * sh.cosine_lobe_l1(-np.asarray(normal)))
    iso = np.zeros_like(lobes)
    iso[..., 0] = share * (np.asarray(flux_plus, np.float64) + np.asarray(flux_minus, np.float64)) * albedo \
        / FLUX_PER_C0
    return np.where(np.asarray(occupied)[..., None], lobes / np.pi, iso)


def closed_box_cells(n: int, block: tuple[int, int, int] | None = None) -> dict[str, np.ndarray]:
    """`cells` of a closed cube in an n^3 grid: one-cell walls one cell in from the grid's edge, each
    fully blocking along its normal, which faces into the box (tools/diffusion_box.py, the tests).
    `block` (lo, hi, top): also a solid block standing on the floor, its one-cell sides over cells lo..hi
    in x and y and its top at z = top, their normals outwards."""
    dims = (n, n, n)
    occ = np.zeros(dims, bool)
    normal = np.zeros((*dims, 3))
    proj = np.zeros((*dims, 3))

    def wall(where, sign: float, axis: int) -> None:
        occ[where] = True
        normal[where] += sign * np.eye(3)[axis]
        proj[where] = np.maximum(proj[where], np.eye(3)[axis])

    for axis in range(3):
        for index, sign in ((1, 1.0), (n - 2, -1.0)):
            sl = [slice(None)] * 3
            sl[2 - axis] = index
            wall(tuple(sl), sign, axis)
    if block is not None:
        lo, hi, top = block
        up, across = slice(2, top + 1), slice(lo, hi + 1)
        for index, sign in ((lo, -1.0), (hi, 1.0)):
            wall((up, across, index), sign, 0)
            wall((up, index, across), sign, 1)
        wall((top, across, across), 1.0, 2)
    length = np.linalg.norm(normal, axis=-1, keepdims=True)
    normal = np.where(length > 0, normal / np.maximum(length, 1e-30), 0.0)
    return cells(occ, normal, proj)


# -- one step ------------------------------------------------------------------------------------------
TRANSFERS = ("cone", "directional")


def directional_matrices() -> np.ndarray:
    """(6, 4, 4) M_d of the `directional` transfer: LPV's improved transfer (lpv_reference.
    gpu_improved_transfer, docs/LPV.md), the L1 projection of L(w) max(0, w.d) / |w|_1, with the flux's
    row weighting the face axis's coefficient by diffusion_propagate.flux_cross instead of m_cross (exact
    for a Lambertian lobe's flux); sum_d M_d = 1."""
    m = np.array(gpu_improved_transfer()[0])
    scale = flux_cross() / improved_constants()["m_cross"]
    m[:, 0, 1:] *= scale  # only the face's own axis is nonzero in that row
    return m


def face_transport(field: np.ndarray, transfer: str | Callable) -> tuple[np.ndarray, np.ndarray]:
    """(raw face fluxes (z, y, x, 6) W, the SH each face carries (z, y, x, 6, 4) per W of them).
    cone (the paper's, normalised): the flux through the face's cone, <L, T_d>, arriving as the uniform
    cone 3 / (2 pi) T_d. directional: the flux of M_d L, arriving as M_d L itself (the light keeps its
    direction within the face's share). A callable field -> (raw, shape) stands for another angular
    model, carried as directional is (tools/diffusion_box.py --alternatives tries more bands and a
    positive closure of the L1 field this way)."""
    if callable(transfer):
        return transfer(field)
    if transfer == "cone":
        shape = (*field.shape[:-1], 6, 4)
        return field @ CONES.T, np.broadcast_to(TRANSFER_NORM * CONES, shape)
    moved = np.einsum("dij,...j->...di", directional_matrices(), field)
    raw = FLUX_PER_C0 * moved[..., 0]
    return raw, moved / np.where(raw > 0.0, raw, 1.0)[..., None]


def face_fluxes(field: np.ndarray, open_faces: np.ndarray, transfer: str = "cone") -> np.ndarray:
    """(z, y, x, 6) W leaving each cell through each face: the transfer's raw face flux (exact for the L1
    intensity) through `outflow`, to the cell's flux max(0, 2 sqrt(pi) c0)."""
    return outflow(face_transport(field, transfer)[0], open_faces, np.maximum(FLUX_PER_C0 * field[..., 0], 0.0))


def outflow(raw: np.ndarray, open_faces: np.ndarray, total: np.ndarray) -> np.ndarray:
    """(z, y, x, 6) W: the raw face fluxes clamped at 0 and kept only on open faces, then scaled so the
    faces carry the cell's whole flux `total` (z, y, x): a field's lobe is negative behind itself, and a
    clamp alone would add light; the scale moves it to the faces it can leave by."""
    kept = np.maximum(raw, 0.0) * open_faces
    s = kept.sum(axis=-1, keepdims=True)
    return np.where(s > 0.0, kept * (total[..., None] / np.where(s > 0.0, s, 1.0)), 0.0)


def carried_shapes(field: np.ndarray, open_faces: np.ndarray, out: np.ndarray, transfer: str) -> np.ndarray:
    """(z, y, x, 6, 4): the SH each face's flux `out` (`face_fluxes`) arrives as, per W of it.
    cone: the face's uniform cone. directional: a face that carries light (raw flux > 0, open) carries
    M_d L plus its share, by raw flux, of the residual L - sum over the carrying faces of M_d L: what the
    clamped and closed faces' M_d L held. So the faces together carry L itself, and each its flux `out`.
    A clamped face's lobe has flux <= 0 but still direction; dropping it (scaling the rest to the flux)
    lost a little of the light's direction at every step, toward isotropy, and a field near a floor
    turned downward and the floor absorbed its own light (docs/DIFFUSION.md, "Transfers")."""
    raw, shape = face_transport(field, transfer)
    if transfer == "cone":
        return shape
    return shared_residual(field, raw, shape * raw[..., None], out)


def shared_residual(field: np.ndarray, raw: np.ndarray, moved: np.ndarray, out: np.ndarray) -> np.ndarray:
    """(z, y, x, 6, K) per W of `out`: each carrying face's (out > 0) field `moved` (z, y, x, 6, K; the
    part of `field` it takes, raw flux `raw`) plus its share by raw flux of the residual, `field` less the
    carrying faces' parts: the faces together carry `field` itself."""
    carrying = out > 0.0
    kept = np.where(carrying[..., None], moved, 0.0)
    raw_kept = np.where(carrying, raw, 0.0)
    total = raw_kept.sum(-1, keepdims=True)
    share = raw_kept / np.where(total > 0.0, total, 1.0)
    residual = field - kept.sum(-2)
    carried = kept + share[..., None] * residual[..., None, :]
    return carried / np.where(carrying, out, 1.0)[..., None]


def inflow(out: np.ndarray) -> np.ndarray:
    """(z, y, x, 6, ...): a[j, d] = what neighbour j - d sends through face d into j (0 from outside)."""
    a = np.zeros_like(out)
    for f, (axis, sign) in enumerate(AXES):
        zyx = 2 - axis
        src = [slice(None)] * 3
        dst = [slice(None)] * 3
        if sign > 0:
            src[zyx], dst[zyx] = slice(0, -1), slice(1, None)
        else:
            src[zyx], dst[zyx] = slice(1, None), slice(0, -1)
        a[tuple(dst) + (f,)] = out[tuple(src) + (f,)]
    return a


def side_weights(normal: np.ndarray) -> np.ndarray:
    """(z, y, x, 6): the share of the inflow through face d (travelling along d) that lands on the plus
    side: 1 when it travels against n, 0 along n, 1/2 parallel to the plane."""
    dn = normal @ DIRECTIONS.T
    return np.where(dn < -SIDE_EPSILON, 1.0, np.where(dn > SIDE_EPSILON, 0.0, 0.5))


def step(field: np.ndarray, cell: dict, transfer: str = "cone") -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """One gather step: (next field, flux absorbed on the plus side, on the minus side), W.

    Each cell gathers its neighbours' face fluxes a_d (`face_fluxes`, `inflow`). An occupied cell's
    surface absorbs block[axis(d)] x a_d (`step_by_face`), split between its sides (`side_weights`); the
    rest, and all of an empty cell's inflow, is carried on as the transfer's SH per W
    (`carried_shapes`): the next field is sum_d carried_d x shape_d, of flux sum_d carried_d (nothing
    is gained). Absorbed light is not re-emitted within the step: each bounce is its own propagation
    (`emit` makes the next emitters)."""
    nxt, absorbed = step_by_face(field, cell, transfer)
    plus = side_weights(cell["normal"])
    return nxt, np.sum(absorbed * plus, -1), np.sum(absorbed * (1.0 - plus), -1)


def step_by_face(field: np.ndarray, cell: dict, transfer: str = "cone") -> tuple[np.ndarray, np.ndarray]:
    """One gather step (`step`): (next field, flux absorbed by the face it came through (z, y, x, 6), W),
    as the far field's grid keeps it (diffusion_far_field)."""
    out = face_fluxes(field, cell["open"], transfer)
    return gather(out, carried_shapes(field, cell["open"], out, transfer), cell)


def gather(out: np.ndarray, carried: np.ndarray, cell: dict) -> tuple[np.ndarray, np.ndarray]:
    """(next field, flux absorbed by the face it came through (z, y, x, 6), W) from each cell's face
    fluxes `out` (z, y, x, 6) and the field each arrives as per W (z, y, x, 6, K): a cell's surface absorbs
    block[axis(d)] of the inflow through face d, the rest is carried on."""
    a = inflow(out)
    shape = inflow(np.ascontiguousarray(carried))
    axis_of_face = np.array([axis for axis, _ in AXES])
    absorbed = a * cell["block"][..., axis_of_face]
    return np.einsum("...d,...dk->...k", a - absorbed, shape), absorbed


def propagate(field: np.ndarray, cell: dict, steps: int,
              transfer: str = "cone") -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """`steps` steps from emitters `field`: (field left in flight, absorbed plus, absorbed minus)."""
    plus = np.zeros(field.shape[:-1])
    minus = np.zeros(field.shape[:-1])
    for _ in range(steps):
        field, p, m = step(field, cell, transfer)
        plus += p
        minus += m
    return field, plus, minus


# -- far field -----------------------------------------------------------------------------------------
# passes/diffusion_far_field.py: a grid of twice the cell carries light beyond the fine grid's near steps;
# far cell j holds fine cells 2j and 2j + 1 on each axis.
_NEIGHBOURS_18 = [o for o in np.ndindex(3, 3, 3) if sum(abs(v - 1) for v in o) in (1, 2)]  # (z, y, x) + 1


def _enclosed(cell: dict) -> np.ndarray:
    return cell["occupied"] & ~cell["open"].any(-1)


def far_move_enclosed(fields: np.ndarray, far_cell: dict, cone: int | None = None) -> np.ndarray:
    """The far grid's emitters (3, z, y, x, 4: rgb fields summed from the fine grid's) with the light of
    each enclosed cell (occupied, no open face) moved to its face and edge neighbours that are not
    enclosed, in proportion to 1e-3 + max(0, u.w): u the unit offset, w the mean direction of the cell's
    light (band 1 of its channels' sum, (y, z, x) in SH order; a cone field's (`cone`, cone_fields.py):
    its cone's axis). It stays where no neighbour takes it."""
    enclosed = _enclosed(far_cell)
    out = np.array(fields, np.float64)
    shape = enclosed.shape
    for z, y, x in zip(*np.nonzero(enclosed), strict=True):
        band1 = fields[:, z, y, x, 1:].sum(axis=0)  # y, z, x
        w = np.array([band1[2], band1[0], band1[1]]) if cone is None else DIRECTIONS[cone]
        w = w / np.linalg.norm(w) if np.linalg.norm(w) > 0 else w
        takers, weights = [], []
        for oz, oy, ox in _NEIGHBOURS_18:
            n = (z + oz - 1, y + oy - 1, x + ox - 1)
            if all(0 <= v < m for v, m in zip(n, shape, strict=True)) and not enclosed[n]:
                u = np.array([ox - 1, oy - 1, oz - 1], np.float64)
                takers.append(n)
                weights.append(1e-3 + max(0.0, float(u @ w) / np.linalg.norm(u)))
        if not takers:
            continue
        light = np.array(fields[:, z, y, x])
        out[:, z, y, x] -= light
        for n, share in zip(takers, np.array(weights) / sum(weights), strict=True):
            out[:, n[0], n[1], n[2]] += share * light
    return out


def _fine_face_weights(cell: dict) -> tuple[np.ndarray, np.ndarray]:
    """(plus, minus), each (z, y, x, 6): a fine side's weight for light through face d: its block on d's
    axis times the share landing on it (`side_weights`), 0 on a side no light reaches."""
    axis_of_face = np.array([axis for axis, _ in AXES])
    to_plus = side_weights(cell["normal"])
    block = cell["block"][..., axis_of_face] * cell["occupied"][..., None]
    return block * to_plus * cell["receives"][..., 0:1], block * (1.0 - to_plus) * cell["receives"][..., 1:2]


def _face_shift(a: np.ndarray, axis: int, sign: float, fill) -> np.ndarray:
    """a (z, y, x, ...) read at cell + sign x the unit vector of `axis` (x, y, z), `fill` outside."""
    zyx = 2 - axis
    pad = [(0, 0)] * a.ndim
    pad[zyx] = (1, 1)
    padded = np.pad(a, pad, constant_values=fill)
    index = [slice(None)] * a.ndim
    index[zyx] = slice(1 + int(sign), padded.shape[zyx] - 1 + int(sign))
    return padded[tuple(index)]


def _tents(shape: tuple, far_shape: tuple, shift: tuple):
    """For each of the 8 far cells around every fine cell centre (the trilinear corners): the index arrays
    of that far cell (clipped) and the tent weight (0 where it is outside the far grid), (z, y, x); the
    far grid starts `shift` (x, y, z) fine cells before the fine one."""
    at = [(np.arange(n) + s + 0.5) * 0.5 - 0.5 for n, s in zip(shape, shift[::-1], strict=True)]
    base = [np.floor(a).astype(int) for a in at]
    for corner in np.ndindex(2, 2, 2):
        idx, tent = [], 1.0
        for axis in range(3):
            j = base[axis] + corner[axis]
            t = at[axis] - base[axis]
            w = (t if corner[axis] else 1.0 - t) * ((j >= 0) & (j < far_shape[axis]))
            shape_of = [-1 if a == axis else 1 for a in range(3)]
            idx.append(np.clip(j, 0, far_shape[axis] - 1).reshape(shape_of))
            tent = tent * w.reshape(shape_of)
        yield tuple(idx), tent


def far_weights(far_cell: dict, cell: dict, shift: tuple = (0, 0, 0)) -> np.ndarray:
    """(far z, y, x, 6): per far cell and face, the sum over the fine cells within one far cell of its
    centre of their sides' weight for the face x the trilinear tent (far_field_weights.comp.glsl says
    why), where the far cell's light through that face came straight from open space (the cell it comes
    from, cell - d, is in the grid and empty); else 0."""
    w_plus, w_minus = _fine_face_weights(cell)
    fine_weight = (w_plus + w_minus) * cell["occupied"][..., None]
    far_shape = far_cell["occupied"].shape
    total = np.zeros((*far_shape, 6))
    for idx, tent in _tents(cell["occupied"].shape, far_shape, shift):
        np.add.at(total, idx, tent[..., None] * fine_weight)
    for f, (axis, sign) in enumerate(AXES):
        from_empty = ~_face_shift(far_cell["occupied"], axis, -sign, True)
        total[..., f] *= from_empty & far_cell["occupied"]
    return total


def far_add(far_faces: np.ndarray, weights: np.ndarray, cell: dict,
            shift: tuple = (0, 0, 0)) -> tuple[np.ndarray, np.ndarray]:
    """What the fine sides (plus, minus; (z, y, x), W) take of the flux the far grid absorbed by the face
    it came through, `far_faces` (far z, y, x, 6): from each of the 8 far cells around the fine centre
    with `weights` (`far_weights`) > 0, the side's weight (`_fine_face_weights`) x the tent x that cell's
    flux / weights. Each far cell's light is shared out whole, and only it."""
    w_plus, w_minus = _fine_face_weights(cell)
    per_weight = np.divide(far_faces, weights, out=np.zeros(weights.shape), where=weights > 0)
    take = np.zeros(w_plus.shape)
    for idx, tent in _tents(cell["occupied"].shape, weights.shape[:3], shift):
        take += tent[..., None] * per_weight[idx]
    take *= cell["occupied"][..., None]
    return np.sum(w_plus * take, -1), np.sum(w_minus * take, -1)


def _coarse_sum_field(field: np.ndarray, far_shape: tuple, shift: tuple = (0, 0, 0)) -> np.ndarray:
    """A fine field (z, y, x, k) summed per far cell (lpv_far_field.source: radiant intensity adds)."""
    return np.stack([_coarse_sum(field[..., k], far_shape, shift) for k in range(field.shape[-1])], -1)


def _coarse_sum(fine: np.ndarray, far_shape: tuple, shift: tuple = (0, 0, 0)) -> np.ndarray:
    """Per far cell the sum of its fine cells, the far grid starting `shift` (x, y, z) fine cells before
    the fine one (fine cells outside the fine grid hold nothing)."""
    padded = np.zeros(tuple(2 * n for n in far_shape))
    padded[tuple(slice(s, s + n) for n, s in zip(fine.shape, shift[::-1], strict=True))] = fine
    cz, cy, cx = far_shape
    return padded.reshape(cz, 2, cy, 2, cx, 2).sum(axis=(1, 3, 5))


# -- reconstruction ------------------------------------------------------------------------------------
def lookup_corners(points_cells: np.ndarray, dims_xyz):
    """The 8 cells whose centres surround each point (n, 3; grid coordinates in cells), as the lookup
    reads them: per corner (cell (n, 3) x y z, clipped into the grid; its trilinear weight raised by
    LOOKUP_WEIGHT_FLOOR (n); whether the unclipped cell is inside the grid (n))."""
    p = np.asarray(points_cells, np.float64) - 0.5
    base = np.floor(p).astype(int)
    frac = p - base
    dims = np.asarray(dims_xyz)
    for k in range(8):
        o = np.array([k & 1, (k >> 1) & 1, k >> 2])
        c = base + o
        t = np.prod(np.where(o, frac, 1.0 - frac), axis=1) + LOOKUP_WEIGHT_FLOOR
        yield np.clip(c, 0, dims - 1), t, np.all((c >= 0) & (c < dims), axis=1)


def lookup(points_cells: np.ndarray, normals: np.ndarray, cell: dict, flux_plus: np.ndarray,
           flux_minus: np.ndarray, cell_area_m2: float) -> np.ndarray:
    """Irradiance / pi (Cycles' Diffuse Indirect) at points (n, 3) in grid coordinates (cells) with unit
    normals (n, 3). Over the 8 cells whose centres surround the point, each occupied one (in the grid)
    gives the irradiance of its side facing n, flux / (area x h^2), weighted by its trilinear weight
    times |n . n_cell| (the surface it holds faces the point's way: a wall's cell does not light the
    floor beside it) and renormalised, over the cells whose side facing n can receive light at all
    (`receives`); where those weights are all 0 but such a neighbour exists the trilinear weights alone;
    where none does, 0 (no surface near: no light known). Every trilinear weight is raised by
    LOOKUP_WEIGHT_FLOOR, so a point at a cell's centre whose own cell cannot receive (a room's corner)
    still reads its neighbours."""
    count = len(points_cells)
    num = np.zeros(count)
    den = np.zeros(count)
    num_t = np.zeros(count)
    den_t = np.zeros(count)
    for cz, t, inside in lookup_corners(points_cells, cell["occupied"].shape[::-1]):
        idx = (cz[:, 2], cz[:, 1], cz[:, 0])
        n_c = cell["normal"][idx]
        dn = np.sum(normals * n_c, axis=1)
        occ = inside & cell["occupied"][idx] & cell["receives"][idx][np.arange(count), np.where(dn >= 0.0, 0, 1)]
        area = np.maximum(cell["area"][idx], 1e-6) * cell_area_m2
        e = np.where(dn >= 0.0, flux_plus[idx], flux_minus[idx]) / area
        w = np.where(occ, t * np.abs(dn), 0.0)
        num += w * e
        den += w
        wt = np.where(occ, t, 0.0)
        num_t += wt * e
        den_t += wt
    value = np.where(den > 0.0, num / np.where(den > 0.0, den, 1.0),
                     np.where(den_t > 0.0, num_t / np.where(den_t > 0.0, den_t, 1.0), 0.0))
    return value / np.pi


def point_source_axis_irradiance(steps=120, size=41, transfer="cone"):
    """An isotropic point source of 1 W in the centre cell of an empty grid: per distance r (cells) along
    +x, the flux entering that cell through its -x face over `steps` steps, which a small receiver facing
    the source absorbs (its irradiance x its area), and the flux still in flight at the end."""
    dims = (size, size, size)
    c = size // 2
    cell = cells(np.zeros(dims, bool), np.zeros((*dims, 3)), np.zeros((*dims, 3)))
    field = np.zeros((*dims, 4))
    field[c, c, c, 0] = 1.0 / FLUX_PER_C0
    through = np.zeros(size)
    for _ in range(steps):
        through += inflow(face_fluxes(field, cell["open"], transfer))[c, c, :, 0]
        field, _, _ = step(field, cell, transfer)
    return through[c:], flux_w(field)
