"""The `gather` passes (gather_quads, gather_form_factor) against closed-form answers (paper 001,
docs/GATHER.md): a probe's captured surfaces become quad lights whose polygon-to-point form factors
are the exact ones, stay bounded beside a wall where point-to-point form factors do not, and in a
uniform field give what the probes' lookup gives."""

import math

import numpy as np
import pytest

from addon.engine.config import GatherConfig, ProbesConfig
from addon.engine.methods.direct import face_planes
from addon.engine.passes import (
    gather_form_factor,
    gather_quads,
    probe_capture,
    probe_lookup,
    probe_project,
    probe_relocate,
)
from addon.engine.probe_grid import ProbeGrid

pytestmark = pytest.mark.gpu

N = 8  # face texels
ALBEDO = 0.5
DIRECT = np.array([1.0, 2.0, 4.0])  # Diffuse Direct everywhere the probes see: L = ALBEDO x DIRECT
RADIANCE = ALBEDO * DIRECT


def _triangles(tris):
    tris = np.asarray(tris, np.float32)
    normals = np.repeat(np.cross(tris[:, 1] - tris[:, 0], tris[:, 2] - tris[:, 0]), 3, axis=0)
    normals /= np.linalg.norm(normals, axis=-1, keepdims=True)
    return {"pos_ws": tris.reshape(-1, 3), "plane_ws": np.repeat(face_planes(tris), 3, axis=0), "normal_ws": normals,
            "bounce_albedo": np.full((len(normals), 3), ALBEDO)}


def _square(z, half):
    """The square [-half, half]^2 at height z (two triangles)."""
    a, b, c, d = [(-half, -half, z), (half, -half, z), (half, half, z), (-half, half, z)]
    return [[a, b, c], [a, c, d]]


def _box(half):
    """The six inner faces of the cube [-half, half]^3."""
    tris = []
    for axis in range(3):
        for sign in (-1.0, 1.0):
            u, v = [e for e in range(3) if e != axis]
            corners = []
            for su, sv in ((-1, -1), (1, -1), (1, 1), (-1, 1)):
                p = np.zeros(3)
                p[axis], p[u], p[v] = sign * half, su * half, sv * half
                corners.append(p)
            tris += [[corners[0], corners[1], corners[2]], [corners[0], corners[2], corners[3]]]
    return tris


def _field(gl, grid, triangles, face_quads):
    """Capture `triangles` around the probes of `grid`, light every texel with DIRECT, build the quads;
    returns (quads, moments, state, offset, atlas, atlas_direct) (offset: every probe at its grid position)."""
    size = grid.atlas_size
    atlas = {p.name: gl.texture(size) for p in probe_capture.ATLAS}
    target = gl.target(list(atlas.values()), gl.depth_texture(size))
    mesh = gl.mesh(gl.program(probe_capture.SPEC), _triangles(triangles), "triangles")
    probe_capture.run(gl, target, atlas, mesh, grid, probe_capture.face_matrices(grid, 100.0))
    moments, state, offset = gl.texture(size), gl.texture(grid.state_size), probe_relocate.allocate(gl, grid)
    probe_capture.moments(gl, atlas, moments, state, grid, 1.0, offset)
    direct = gl.texture(size, data=np.broadcast_to(np.float32([*DIRECT, 0.0]), (size[1], size[0], 4)))
    quads = gather_quads.allocate(gl, grid, face_quads)
    gather_quads.texels(gl, atlas, direct, quads, grid, offset)
    gather_quads.quads(gl, quads, grid, face_quads)
    return quads, moments, state, offset, atlas, direct


def _receivers(gl, points, normals):
    k = len(points)
    pos = np.c_[np.asarray(points, np.float64), np.ones(k)].astype(np.float32).reshape(1, k, 4)
    nrm = np.asarray(normals, np.float64)
    nrm = np.c_[nrm / np.linalg.norm(nrm, axis=1, keepdims=True), np.zeros(k)].astype(np.float32).reshape(1, k, 4)
    return gl.texture((k, 1), data=pos), gl.texture((k, 1), data=nrm)


def _gather(gl, grid, field, points, normals, probes=None, config=None):
    quads, moments, state, offset, _, _ = field
    probes, config = probes or ProbesConfig(), config or GatherConfig()
    pos, nrm = _receivers(gl, points, normals)
    out = gl.texture((len(points), 1))
    gather_form_factor.run(gl, pos, nrm, quads, moments, state, offset, out, grid, probes, config)
    return gl.read(out)[0, :, :3].astype(np.float64)


def parallel_square_form_factor(point, half, z):
    """The form factor at `point` (normal +z, below the square) of the square [-half, half]^2 at height z:
    the rectangle-to-corner closed form G(a, b) for a receiver under one corner of an a x b rectangle at
    height h, A = a / h, B = b / h:
        G = 1 / (2 pi) [A / sqrt(1 + A^2) atan(B / sqrt(1 + A^2)) + B / sqrt(1 + B^2) atan(A / sqrt(1 + B^2))],
    odd in a and b, summed with signs over the square's corners relative to the receiver."""
    h = z - point[2]

    def g(a, b):
        x, y = a / h, b / h
        sx, sy = math.sqrt(1 + x * x), math.sqrt(1 + y * y)
        return (x / sx * math.atan(y / sx) + y / sy * math.atan(x / sy)) / (2 * math.pi)

    x0, x1 = -half - point[0], half - point[0]
    y0, y1 = -half - point[1], half - point[1]
    return g(x1, y1) - g(x0, y1) - g(x1, y0) + g(x0, y0)


def numeric_form_factor(point, normal, half, z, samples=1500):
    """The same square's form factor at a tilted receiver by midpoint quadrature of
    cos_x cos_e / (pi r^2) dA, cos_x clamped at 0 (the horizon): independent of Lambert's formula."""
    c = (np.arange(samples) + 0.5) / samples * 2 * half - half
    x, y = np.meshgrid(c, c)
    v = np.stack([x - point[0], y - point[1], np.full_like(x, z - point[2])], axis=-1)
    r2 = (v * v).sum(-1)
    cos_x = np.maximum(v @ (np.asarray(normal) / np.linalg.norm(normal)), 0.0) / np.sqrt(r2)
    cos_e = (z - point[2]) / np.sqrt(r2)
    return float((cos_x * cos_e / (math.pi * r2)).sum() * (2 * half / samples) ** 2)


# One probe at the origin; the square [-1, 1]^2 at z = 1 fills exactly its +z face (no other face sees
# it), so its texels' planes rebuild it exactly: whole quads inside, the texels one by one in the quads
# at the face's edges (their corners border directions that see nothing).
GRID = ProbeGrid(np.zeros(3), 1.0, (1, 1, 1), N)
POINTS = [(0.0, 0.0, 0.0), (0.2, -0.1, 0.3), (-0.35, 0.25, -0.4), (0.6, 0.5, 0.5)]


@pytest.mark.parametrize("face_quads", [2, 4, 8])
def test_a_point_under_a_uniform_square_gets_the_closed_form(gl, face_quads):
    # Diffuse Indirect = L F, F the parallel square's closed form (0.36 to 0.70 at these points). The
    # quads tile the square exactly, and form factors add, so the only error is fp32 rounding in the
    # corner distances and the atan2 sums: measured <= 1.2e-5 relative (M = 2, 4, 8); rtol 1e-4. A wrong unit (pi),
    # a missing horizon, a seam or a floating quad would be > 1e-2.
    field = _field(gl, GRID, _square(1.0, 1.0), face_quads)
    got = _gather(gl, GRID, field, POINTS, [(0, 0, 1)] * len(POINTS), config=GatherConfig(face_quads=face_quads))
    expected = np.array([parallel_square_form_factor(p, 1.0, 1.0) for p in POINTS])[:, None] * RADIANCE
    np.testing.assert_allclose(got, expected, rtol=1e-4)


def test_the_horizon_clips_quads_a_tilted_receiver_sees_in_part(gl):
    # Receivers tilted so their tangent plane cuts the square: only the part above the horizon lights
    # them (F = 0.402 and 0.191). Reference: midpoint quadrature of cos_x cos_e / (pi r^2) over 1500^2
    # cells (within 3e-7 of 3000^2 cells); measured within 3.1e-6; rtol 1e-3. Without the clip the part
    # below the horizon would count with a negative sign (Lambert's formula is signed).
    points = [(0.1, 0.0, 0.5), (-0.3, 0.2, 0.0)]
    normals = [(1.0, 0.0, 0.4), (0.0, -1.0, 0.2)]
    field = _field(gl, GRID, _square(1.0, 1.0), 4)
    got = _gather(gl, GRID, field, points, normals)
    f = [numeric_form_factor(p, n, 1.0, 1.0) for p, n in zip(points, normals, strict=True)]
    expected = np.array(f)[:, None] * RADIANCE
    np.testing.assert_allclose(got, expected, rtol=1e-3)


def test_a_point_1_mm_from_a_lit_wall_stays_bounded(gl):
    # A receiver 1 mm below the square, facing it, under the centre of a whole quad (M = 4: the quad
    # [-0.5, 0]^2 at z = 1). Polygon form factors: F = 1 - 1.0e-6 (the closed form; at most 1 however
    # close), so Diffuse Indirect = L to fp32 rounding (measured 1 + 1.5e-6: bounded by L (1 + 1e-5)).
    # The point-to-point baseline puts that quad's 0.25 m^2 at 1 mm: A / (pi r^2) = 8e4, a spike.
    # Visibility is off: the normal bias would test the probe's view from behind the wall, which the
    # probes' own tests cover; here the form factor alone is measured.
    probes = ProbesConfig(chebyshev_visibility=False)
    point = (-0.25, -0.25, 0.999)
    field = _field(gl, GRID, _square(1.0, 1.0), 4)
    polygon = _gather(gl, GRID, field, [point], [(0, 0, 1)], probes)[0]
    f = parallel_square_form_factor(point, 1.0, 1.0)
    assert 0.999 < f < 1.0
    np.testing.assert_allclose(polygon, f * RADIANCE, rtol=1e-4)
    assert np.all(polygon <= RADIANCE * (1 + 1e-5))
    point_ff = _gather(gl, GRID, field, [point], [(0, 0, 1)], probes, GatherConfig(form_factor="point"))[0]
    assert np.all(np.isfinite(point_ff)) and np.all(point_ff > 1e3 * RADIANCE)


def test_far_from_walls_in_a_uniform_field_gather_equals_probes(gl):
    # 2 x 2 x 2 probes 0.5 m apart inside a closed cube of half-side 2 m whose every texel brings L:
    # from anywhere inside, any normal, E = pi L, so the probes' lookup gives L (to fp32, tests/gpu/
    # test_probes.py) and so must the gather. Its quads are exact on the cube's planes; the texels that
    # straddle the cube's edges (seen off-centre, where its planes meet) are each rebuilt on the plane
    # their centre sees, so a sliver at each edge is counted twice or not at all: measured within
    # 0.13 % of L; rtol 5e-3.
    grid = ProbeGrid(np.full(3, -0.25), 0.5, (2, 2, 2), N)
    field = _field(gl, grid, _box(2.0), 4)
    rng = np.random.default_rng(5)
    points = rng.uniform(-0.4, 0.4, (16, 3))
    normals = rng.normal(size=(16, 3))
    got = _gather(gl, grid, field, points, normals)
    _, moments, state, offset, atlas, direct = field
    sh = gl.texture(grid.sh_size)
    probe_project.run(gl, atlas, direct, sh, grid)
    pos, nrm = _receivers(gl, points, normals)
    out = gl.texture((len(points), 1))
    probe_lookup.run(gl, pos, nrm, {"sh": sh, "moments": moments, "state": state, "probe_offset": offset}, out,
                     grid, ProbesConfig())
    probes = gl.read(out)[0, :, :3].astype(np.float64)
    np.testing.assert_allclose(probes, np.broadcast_to(RADIANCE, probes.shape), rtol=1e-4)
    np.testing.assert_allclose(got, probes, rtol=5e-3)
