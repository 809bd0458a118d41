"""numpy twin of the octree LPV (`lpv --variant octree`, paper 002): mip chain, per-level propagation,
coarse-to-fine merge with the index rule.

Paper 002 (Olovsson) stores the LPV as a full octree laid out as a mip chain of dense grids O_0 (the
LPV grid) .. O_{L-1}, each cell of level i covering 2^i x 2^i x 2^i cells of level 0. Light is
injected into O_0, each coarser level is built from the one below it (`downsample`), every level
propagates on its own for k steps, and the levels are merged coarse to fine into one grid, read with the
ordinary lookup. Which level a cell reads is the index rule: I(x) = the finest level holding light at
x (the thesis' I(x) = min_i I_i(x / 2^i), with I_i = i where O_i is non-zero).

This module is the reference of passes/lpv_octree.py and its shaders (tests/gpu/test_lpv.py checks the
GPU against it); it computes in float64 what the GPU computes in fp32. Conventions are lpv_reference's:
a field is an array (z, y, x, 4) of L1 SH of radiant intensity (W/sr) per cell; an accumulation holds
the path-weighted sum of the propagated snapshots (W/sr x cells).

Units across levels (the thesis leaves them unstated; its box *average* keeps "a uniform range of
intensities" in its own unnormalised scheme):
- A coarse cell emits what its eight children emit: intensity is additive, so `downsample` sums. The
  flux of every level is the injected flux.
- The lookup reads E = c . lobe / h^2 from an accumulation on cells of side h, so one light field gives
  the same reading from levels i and i + 1 when acc_i = acc_{i+1} / 4 ((h / 2h)^2): `upsample` carries
  a coarse accumulation to the finer level with that factor (as lpv_far_field.add does).
- Geometry: a coarse cell's projected area along an axis is its children's sum / 4 (cells^2 of a cell
  twice as wide), its surface offset their area-weighted mean position (`downsample_voxels`, the twin of
  lpv/far_field_voxels.comp.glsl).

The merge (`merge`): M_{L-1} = acc_{L-1}; for i = L-2 .. 0, with U = upsample(M_{i+1}),
    M_i = w A_i + (1 - w) U,    w = clamp(rho / eps - 1, 0, 1),    rho = light(A_i) / light(U),
light() = the sum over colours of c0 (the cell's flux up to 2 sqrt(pi)), shared by the colours so the
blend shifts no hue. A finer level counts where its light reaches eps times the coarser answer there,
fully from 2 eps: with eps -> 0 this is the paper's rule ("non-zero", the finest level with light wins,
a hard switch); a larger eps also skips a finer level whose light has not yet arrived (k steps carry
light about k / 2 cells: its reading there is a small fraction of the coarser level's), and the ramp
makes the switch continuous in the light, so a light that moves a little changes the image a little.
Each merged coefficient lies between the finer level's and the coarser answer's: the merge creates no
light. Where the coarser answer is not positive the finer level is taken whenever it holds light.

The time merge (`add_up`, LpvConfig.octree_merge = "time"): each level accumulates its steps with the
shares of passes/lpv_octree.time_share (by time of flight; they sum to 1 over the levels at every
time), and the levels are added: M_i = A_i + upsample(M_{i+1}).
"""

from __future__ import annotations

import numpy as np

from . import lpv_reference as ref


def level_dims(dims: tuple[int, int, int], levels: int) -> list[tuple[int, int, int]]:
    """(x, y, z) cells of levels 0 .. levels-1: level i + 1 has ceil(level i / 2) per axis (its cell j
    holds cells 2j and 2j + 1 of level i; on odd axes the last one lies partly outside level i)."""
    out = [tuple(int(d) for d in dims)]
    for _ in range(levels - 1):
        out.append(tuple((d + 1) // 2 for d in out[-1]))
    return out


def _pad_even(field: np.ndarray) -> np.ndarray:
    return np.pad(field, [(0, s % 2) for s in field.shape[:3]] + [(0, 0)] * (field.ndim - 3))


def downsample(field: np.ndarray) -> np.ndarray:
    """The next coarser level's snapshot: per coarse cell the sum of its 2 x 2 x 2 children (children
    beyond odd dims hold nothing)."""
    f = _pad_even(np.asarray(field, np.float64))
    z, y, x = (s // 2 for s in f.shape[:3])
    return f.reshape(z, 2, y, 2, x, 2, *f.shape[3:]).sum(axis=(1, 3, 5))


def downsample_voxels(projected: np.ndarray, offset: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The next coarser level's (vox_projected, vox_offset), each (z, y, x, 4): per axis the children's
    projected areas summed / 4, w = surface area summed / 4; offsets: the children's surface positions
    (child centre -+ 0.5 cells plus its offset) averaged with their projected area as weight, halved
    into coarse cells, 0 where no child projects along the axis."""
    p = _pad_even(np.asarray(projected, np.float64))
    o = _pad_even(np.asarray(offset, np.float64))
    z, y, x = (s // 2 for s in p.shape[:3])
    p6 = p.reshape(z, 2, y, 2, x, 2, 4)
    o6 = o.reshape(z, 2, y, 2, x, 2, 4)
    corner = np.zeros((1, 2, 1, 2, 1, 2, 3))
    corner[0, :, 0, :, 0, :, 2] = np.array([0.0, 1.0])[:, None, None]  # z
    corner[0, :, 0, :, 0, :, 1] = np.array([0.0, 1.0])[None, :, None]  # y
    corner[0, :, 0, :, 0, :, 0] = np.array([0.0, 1.0])[None, None, :]  # x
    area = p6[..., :3].sum(axis=(1, 3, 5))
    moment = (p6[..., :3] * (corner - 0.5 + o6[..., :3])).sum(axis=(1, 3, 5))
    out_p = np.concatenate([area, p6[..., 3:].sum(axis=(1, 3, 5))], axis=-1) / 4.0
    off = np.where(area > 0, 0.5 * moment / np.maximum(area, 1e-300), 0.0)
    return out_p, np.concatenate([off, np.zeros(area.shape[:3] + (1,))], axis=-1)


def chain(injected: np.ndarray, levels: int) -> list[np.ndarray]:
    """The injected snapshot of every level: level 0 as given, each coarser one `downsample`d."""
    out = [np.asarray(injected, np.float64)]
    for _ in range(levels - 1):
        out.append(downsample(out[-1]))
    return out


def propagate(snapshots: list[np.ndarray], steps, throughs=None, shares=None) -> list[np.ndarray]:
    """Every level's accumulation after its improved-transport steps, as the GPU pass runs them
    (lpv_reference.gpu_improved_transfer). steps: one count for every level, or one per level;
    throughs: per level lpv_reference.pass_through's shares, or None in empty space; shares: per level
    a function (step, 1-based) -> the weight that step is accumulated with (the time merge's
    passes/lpv_octree.time_share), or None for 1."""
    matrices, path = ref.gpu_improved_transfer()
    n = len(snapshots)
    steps = [steps] * n if np.isscalar(steps) else steps
    throughs = throughs or [None] * n
    shares = shares or [None] * n
    out = []
    for field, count, through, share in zip(snapshots, steps, throughs, shares, strict=True):
        acc, current = np.zeros(np.shape(field)), np.asarray(field, np.float64)
        for s in range(1, count + 1):
            current = ref.step(current, matrices, through)
            acc += (1.0 if share is None else share(s)) * (current @ path.T)
        out.append(acc)
    return out


def upsample(coarse: np.ndarray, fine_shape: tuple[int, ...]) -> np.ndarray:
    """A coarse accumulation read at the finer level's cell centres, in its units: 1/4 x trilinear at
    coarse coordinate (i + 0.5) / 2 - 0.5 (coarse centres at integers), clamped to the edge cells.
    `fine_shape`: (z, y, x) of the finer level."""
    coarse = np.asarray(coarse, np.float64)
    out = np.zeros(tuple(fine_shape[:3]) + coarse.shape[3:])
    per_axis = []
    for n_fine, n_coarse in zip(fine_shape[:3], coarse.shape[:3], strict=True):
        t = (np.arange(n_fine) + 0.5) / 2.0 - 0.5
        i0 = np.floor(t).astype(int)
        per_axis.append(((np.clip(i0, 0, n_coarse - 1), 1.0 - (t - i0)), (np.clip(i0 + 1, 0, n_coarse - 1), t - i0)))
    (z_lo, z_hi), (y_lo, y_hi), (x_lo, x_hi) = per_axis
    for kz, wz in (z_lo, z_hi):
        for ky, wy in (y_lo, y_hi):
            for kx, wx in (x_lo, x_hi):
                w = wz[:, None, None] * wy[None, :, None] * wx[None, None, :]
                out += w[..., None] * coarse[np.ix_(kz, ky, kx)]
    return 0.25 * out


def light(channels: list[np.ndarray]) -> np.ndarray:
    """The light() of the merge rule: c0 summed over the colour channels, per cell."""
    return sum(np.asarray(c, np.float64)[..., 0] for c in channels)


def weight(fine_light: np.ndarray, coarse_light: np.ndarray, epsilon: float) -> np.ndarray:
    """The finer level's share w of the merge at each cell (module docstring): clamp(rho / eps - 1, 0,
    1), rho = fine / coarse light; where the coarser light is not positive, 1 if the finer holds light."""
    fine_light, coarse_light = np.asarray(fine_light, np.float64), np.asarray(coarse_light, np.float64)
    positive = coarse_light > 0.0
    ratio = fine_light / np.where(positive, epsilon * coarse_light, 1.0)
    return np.where(positive, np.clip(ratio - 1.0, 0.0, 1.0), (fine_light > 0.0).astype(np.float64))


def merge(accumulations: list[list[np.ndarray]], epsilon: float) -> tuple[list[np.ndarray], list[np.ndarray]]:
    """(merged level 0 per colour channel, the finer level's weight w at every level but the coarsest).
    accumulations: per level (finest first) the three colour channels' accumulations."""
    merged = [np.asarray(c, np.float64) for c in accumulations[-1]]
    weights = []
    for fine in reversed(accumulations[:-1]):
        up = [upsample(m, np.shape(f)) for m, f in zip(merged, fine, strict=True)]
        w = weight(light(fine), light(up), epsilon)
        merged = [w[..., None] * np.asarray(f, np.float64) + (1.0 - w[..., None]) * u
                  for f, u in zip(fine, up, strict=True)]
        weights.insert(0, w)
    return merged, weights


def add_up(accumulations: list[list[np.ndarray]]) -> list[np.ndarray]:
    """The time merge: M_{L-1} = acc_{L-1}, M_i = acc_i + upsample(M_{i+1}); per colour channel."""
    merged = [np.asarray(c, np.float64) for c in accumulations[-1]]
    for fine in reversed(accumulations[:-1]):
        merged = [np.asarray(f, np.float64) + upsample(m, np.shape(f)) for f, m in zip(fine, merged, strict=True)]
    return merged


def index_volume(weights: list[np.ndarray]) -> np.ndarray:
    """I at level-0 cells (z, y, x) for a hard switch (every weight 0 or 1): the level whose light the
    merge kept there, I(x) = i for the finest i with w_i(x >> i) = 1, else the coarsest level. With a
    ramp it is the finest level with a full share."""
    levels = len(weights) + 1
    shape0 = np.shape(weights[0]) if weights else (1, 1, 1)
    index = np.full(shape0, levels - 1)
    for i in reversed(range(levels - 1)):
        z, y, x = np.indices(shape0)
        full = weights[i][z >> i, y >> i, x >> i] >= 1.0
        index = np.where(full, i, index)
    return index
