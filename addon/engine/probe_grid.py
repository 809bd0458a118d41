"""The probe grid of method `probes` (paper 004; docs/PROBES.md): placement, the atlas layout of the
probes' six faces, the faces' frames and view-projections, and the closed-form solid angle of a face
texel. The numpy reference of gpu_shaders/probes/probe.glsl.

Placement: spacing = the bounds' longest side / probes_per_side; each axis gets as many probes as its
extent needs at that spacing (at least one, so a flat scene gets a flat grid), centred on the bounds, so
the outermost probes sit half a spacing inside the outer walls.

Faces: face f = 2 * axis + (1 if negative) looks along its `forward` axis; texel (i, j) of a face of
n x n texels (i: column, j: row, GL row 0 at the bottom) looks along forward + s right + t up with
s = 2 (i + 0.5) / n - 1 and t = 2 (j + 0.5) / n - 1: the face's view-projection maps that direction to
NDC (s, t), so the rasterized texel and the direction the shaders give it agree.

Atlas: probe p = ix + nx (iy + ny iz) owns a tile of 3n x 2n texels, face f at tile column f % 3, row
f // 3; tiles fill rows of `tiles_per_row`. The SH table is (9 nx) x (ny nz) texels: coefficient c of
probe (ix, iy, iz) at (c nx + ix, iy + ny iz).

Relocation (DDGI's idea, this rule: docs/PROBES.md, "Relocation"): `relocation_step` moves a probe out of
a solid it sits in, or off the surfaces near it, from its own capture; the numpy twin of
gpu_shaders/probes/relocate.comp.glsl.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

SH_COEFFS = 9  # L2: the paper's nine coefficients per colour

# forward, right, up per face (face = 2 * axis + negative); right x up = forward for every face.
FACE_FRAMES = np.array([
    [(1, 0, 0), (0, 1, 0), (0, 0, 1)],
    [(-1, 0, 0), (0, -1, 0), (0, 0, 1)],
    [(0, 1, 0), (0, 0, 1), (1, 0, 0)],
    [(0, -1, 0), (0, 0, -1), (1, 0, 0)],
    [(0, 0, 1), (1, 0, 0), (0, 1, 0)],
    [(0, 0, -1), (-1, 0, 0), (0, 1, 0)],
], np.float64)


@dataclass(frozen=True)
class ProbeGrid:
    first_m: np.ndarray          # position of probe (0, 0, 0), m
    spacing_m: float
    dims: tuple[int, int, int]
    face_texels: int             # n: each face is n x n texels

    @classmethod
    def fit(cls, lo: np.ndarray, hi: np.ndarray, probes_per_side: int, face_texels: int, triangles: int = 0,
            max_triangle_draws: float = math.inf) -> ProbeGrid:
        """The grid of `probes_per_side`, or of fewer (down to 2) while 6 x probes x `triangles` exceeds
        `max_triangle_draws` (the capture draws the scene once per face)."""
        grid = cls._fit(lo, hi, probes_per_side, face_texels)
        while probes_per_side > 2 and 6.0 * grid.count * triangles > max_triangle_draws:
            probes_per_side -= 1
            grid = cls._fit(lo, hi, probes_per_side, face_texels)
        return grid

    @classmethod
    def _fit(cls, lo: np.ndarray, hi: np.ndarray, probes_per_side: int, face_texels: int) -> ProbeGrid:
        lo, hi = np.asarray(lo, np.float64), np.asarray(hi, np.float64)
        extent = np.maximum(hi - lo, 0.0)
        spacing = max(float(extent.max()), 1e-6) / probes_per_side
        # ceil with a tolerance: an axis of exactly k spacings gets k probes, not k + 1 from rounding.
        dims = np.maximum(np.ceil(extent / spacing - 1e-6).astype(int), 1)
        first = (lo + hi) / 2.0 - (dims - 1) * spacing / 2.0
        return cls(first, spacing, tuple(int(d) for d in dims), int(face_texels))

    @property
    def count(self) -> int:
        return int(np.prod(self.dims))

    def positions_m(self) -> np.ndarray:
        """(count, 3) probe positions in probe order p = ix + nx (iy + ny iz)."""
        nx, ny, nz = self.dims
        iz, iy, ix = np.meshgrid(np.arange(nz), np.arange(ny), np.arange(nx), indexing="ij")
        idx = np.stack([ix.ravel(), iy.ravel(), iz.ravel()], axis=-1)
        return self.first_m + idx * self.spacing_m

    @property
    def tiles_per_row(self) -> int:
        """Tiles per atlas row: about as many rows of tiles (2n high) as columns (3n wide)."""
        return max(1, min(self.count, math.ceil(math.sqrt(self.count * 2.0 / 3.0))))

    @property
    def atlas_size(self) -> tuple[int, int]:
        return self.tiled_size(self.face_texels)

    def tiled_size(self, n: int) -> tuple[int, int]:
        """An atlas of every probe's six n x n faces in the capture's tile layout."""
        cols = self.tiles_per_row
        rows = -(-self.count // cols)
        return 3 * n * cols, 2 * n * rows

    @property
    def sh_size(self) -> tuple[int, int]:
        nx, ny, nz = self.dims
        return SH_COEFFS * nx, ny * nz

    @property
    def state_size(self) -> tuple[int, int]:
        nx, ny, nz = self.dims
        return nx, ny * nz

    def face_origin(self, probe: int, face: int) -> tuple[int, int]:
        """The atlas texel (x, y) of the face's texel (0, 0)."""
        n, cols = self.face_texels, self.tiles_per_row
        return 3 * n * (probe % cols) + n * (face % 3), 2 * n * (probe // cols) + n * (face // 3)

    def read_by(self, lo_m: np.ndarray, hi_m: np.ndarray, margin_m: float) -> np.ndarray:
        """(count,) bool in probe order: the probes a lookup at a point of some box [lo_m[i], hi_m[i]]
        (triangles' bounds) moved up to margin_m (the normal bias) can read, i.e. the corners of every
        probe cell such a point falls in, with the lookup's own clamping of cells to [0, dims - 2]
        (probes/lookup.comp.glsl). Every other probe is never weighted: capturing and lighting it is
        wasted. Conservative: a box stands for its triangle, and the margin is widened by 1e-4 spacing
        so the GPU's float32 rounding at a cell border cannot reach a probe left out."""
        dims = np.array(self.dims)
        needed = np.zeros(self.count, bool)
        if len(lo_m) == 0:
            return needed
        pad = margin_m + 1e-4 * self.spacing_m
        top = np.maximum(dims - 2, 0)
        cell = lambda x: np.clip(np.floor((x - self.first_m) / self.spacing_m), 0, top).astype(int)  # noqa: E731
        i0 = cell(np.asarray(lo_m, np.float64) - pad)
        i1 = np.minimum(cell(np.asarray(hi_m, np.float64) + pad) + 1, dims - 1)  # + 1: a cell's far corners
        # Mark every box's probe range at once: a 3D difference array, summed along each axis.
        marks = np.zeros(tuple(dims[::-1] + 1), np.int64)  # (z, y, x)
        for corner in range(8):
            bits = [(corner >> axis) & 1 for axis in range(3)]
            idx = [np.where(b, i1[:, axis] + 1, i0[:, axis]) for axis, b in enumerate(bits)]
            np.add.at(marks, (idx[2], idx[1], idx[0]), (-1) ** sum(bits))
        covered = marks.cumsum(0).cumsum(1).cumsum(2)[:-1, :-1, :-1] > 0
        needed[:] = covered.ravel()  # (z, y, x) ravelled is probe order ix + nx (iy + ny iz)
        return needed

    def uniforms(self) -> dict:
        """What the probe shaders need of the grid (probe.glsl)."""
        return {"probe_first": self.first_m, "probe_spacing": self.spacing_m, "probe_dims": self.dims,
                "face_texels": self.face_texels, "tiles_per_row": self.tiles_per_row}


def texel_directions(n: int) -> np.ndarray:
    """(6, n, n, 3) unit directions of every face texel's centre, [face, row j, column i]."""
    c = 2.0 * (np.arange(n) + 0.5) / n - 1.0
    t, s = np.meshgrid(c, c, indexing="ij")
    f, r, u = FACE_FRAMES[:, 0], FACE_FRAMES[:, 1], FACE_FRAMES[:, 2]
    d = f[:, None, None] + s[None, ..., None] * r[:, None, None] + t[None, ..., None] * u[:, None, None]
    return d / np.linalg.norm(d, axis=-1, keepdims=True)


def _corner_area(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Solid angle of the face-plane rectangle [0, x] x [0, y] at distance 1: atan2(xy, sqrt(x^2+y^2+1))."""
    return np.arctan2(x * y, np.sqrt(x * x + y * y + 1.0))


def texel_solid_angles(n: int) -> np.ndarray:
    """(n, n) exact solid angle (sr) of each texel of an n x n face, [row j, column i]: the paper's closed
    form A(x1, y1) - A(x0, y1) - A(x1, y0) + A(x0, y0). Six faces sum to 4 pi."""
    e = 2.0 * np.arange(n + 1) / n - 1.0
    x0, x1 = e[:-1][None, :], e[1:][None, :]
    y0, y1 = e[:-1][:, None], e[1:][:, None]
    return _corner_area(x1, y1) - _corner_area(x0, y1) - _corner_area(x1, y0) + _corner_area(x0, y0)


def face_view_projection(center_m: np.ndarray, face: int, near_m: float, far_m: float) -> np.ndarray:
    """4x4 (column vectors) mapping a world point to the face's clip space: x_ndc = v.right / v.forward,
    y_ndc = v.up / v.forward (v = p - center), depth the usual perspective depth in [near, far]."""
    f, r, u = FACE_FRAMES[face]
    c = np.asarray(center_m, np.float64)
    a = (far_m + near_m) / (far_m - near_m)
    b = -2.0 * far_m * near_m / (far_m - near_m)
    m = np.zeros((4, 4))
    m[0, :3], m[0, 3] = r, -r @ c
    m[1, :3], m[1, 3] = u, -u @ c
    m[2, :3], m[2, 3] = a * f, -a * (f @ c) + b
    m[3, :3], m[3, 3] = f, -f @ c
    return m


# Relocation (docs/PROBES.md, "Relocation"). A probe ends at least this far (x spacing) from the surfaces
# near it. Measured (128 px against Cycles, rel_rmse_8): window-room at two bounces 0.243 at 0.1 and 0.15,
# 0.248 at 0.2, 0.250 at 0.25, 0.257 at 0.35, 0.278 at 0.45; cornell 0.1230 at 0.15, 0.1223 at 0.25,
# 0.1220 at 0.35. At 0.1 only the floor's and ceiling's probe layers move (out of the slabs; 509 of the
# 1804 lit probes): the gain is theirs, and wider clearances, which push more probes off the walls, lose
# some of it.
RELOCATE_CLEARANCE_RATIO = 0.15
# The largest move along each axis, x spacing: below 0.5 a probe stays inside the half cells around its
# grid position, so the trilinear cell structure (cells from the grid positions) still holds.
RELOCATE_MAX_OFFSET_RATIO = 0.45
# Inside a solid: no direction escapes to the sky and back faces fill more than this share of the sphere.
# A closed solid's inside sees geometry in every direction, so an open room with flipped normals (back
# faces everywhere, sky through its opening) is not mistaken for one.
RELOCATE_INSIDE_SHARE = 0.5
# A probe leaving a solid must end at least this far (x spacing) beyond the face it leaves through, where
# the offset bound keeps it from the full clearance: nearer, its capture would still graze that face.
RELOCATE_MIN_EXIT_RATIO = 0.1
# A step shorter than this (x spacing) is float rounding of a probe already in place: it stays, and is
# not captured again.
RELOCATE_MIN_STEP_RATIO = 1e-3
# Steps per geometry change, each followed by a capture of the probes it moved. The first moves probes
# out of solids and off the surfaces near them (every near plane at once); the second moves a probe that
# left a solid off the surfaces it then finds near (a floor slab meeting a wall).
RELOCATE_ROUNDS = 2


def relocation_step(grid_position_m: np.ndarray, offset_m: np.ndarray, seen_m: np.ndarray, normal: np.ndarray,
                    side: np.ndarray, hit: np.ndarray, spacing_m: float, lo_m: np.ndarray,
                    hi_m: np.ndarray) -> np.ndarray:
    """The probe's new offset (3,) (m) from its capture at grid_position_m + offset_m. Texel arrays in
    capture order (6, n, n[, 3]): seen_m the surface point each texel sees, normal its unit normal turned
    towards the probe, side +1 front / -1 back face, hit whether it sees geometry at all; [lo_m, hi_m] the
    occupied bounds the grid was fitted to.

    Inside (no texel misses, back faces over RELOCATE_INSIDE_SHARE of the sphere): out through a back
    face, along its plane's normal to clearance c = RELOCATE_CLEARANCE_RATIO spacing beyond it, the
    offset clamped to the bound. An exit counts if it ends at least RELOCATE_MIN_EXIT_RATIO spacing
    beyond the face and within the bounds (a floor slab's probe leaves upwards, into the room, even where
    its bottom face is nearer: below the floor no receiver reads it); of those, the nearest face's. None:
    stay (part-way leaves it inside). Otherwise, for each texel whose point
    lies within c (texels in capture order, each step from the position so far): if the probe is less
    than c in front of that texel's plane, step along the plane's normal to c from it (a projection onto
    each near half-space in turn: a corner's planes in one pass). The offset is clamped to
    RELOCATE_MAX_OFFSET_RATIO spacing per axis; a change below RELOCATE_MIN_STEP_RATIO spacing is none."""
    offset = np.asarray(offset_m, np.float64)
    pos = np.asarray(grid_position_m, np.float64) + offset
    seen, nrm = np.asarray(seen_m, np.float64), np.asarray(normal, np.float64)
    hit, back = np.asarray(hit, bool), np.asarray(side) < 0
    clearance, bound = RELOCATE_CLEARANCE_RATIO * spacing_m, RELOCATE_MAX_OFFSET_RATIO * spacing_m
    n = seen.shape[1]
    omega = np.broadcast_to(texel_solid_angles(n), (6, n, n))
    plane_m = np.einsum("...k,...k->...", pos - seen, nrm)  # the probe's height over each texel's plane
    step = np.zeros(3)
    if hit.all() and omega[back].sum() > RELOCATE_INSIDE_SHARE * 4.0 * math.pi:
        exit_height = math.inf
        for t in np.flatnonzero(back.ravel()):
            x, outward, height = seen.reshape(-1, 3)[t], -nrm.reshape(-1, 3)[t], plane_m.ravel()[t]
            out = np.clip(offset + outward * (height + clearance), -bound, bound)
            end = np.asarray(grid_position_m, np.float64) + out
            if (height < exit_height and (end - x) @ outward >= RELOCATE_MIN_EXIT_RATIO * spacing_m
                    and np.all(end >= lo_m) and np.all(end <= hi_m)):
                exit_height, step = height, out - offset
        if exit_height == math.inf:
            return offset
    else:
        near = hit & (np.linalg.norm(seen - pos, axis=-1) < clearance)
        for t in np.flatnonzero(near.ravel()):
            height = (pos + step - seen.reshape(-1, 3)[t]) @ nrm.reshape(-1, 3)[t]
            if height < clearance:
                step += nrm.reshape(-1, 3)[t] * (clearance - height)
    moved = np.clip(offset + step, -bound, bound)
    return moved if np.abs(moved - offset).max() > RELOCATE_MIN_STEP_RATIO * spacing_m else offset
