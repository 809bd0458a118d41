"""The `probes` passes (probe_capture, probe_project, probe_lookup) against closed-form answers.

fp32 sums of 6 n^2 = 384 texel terms of order 1 round to ~1e-6 relative; RTOL = 1e-5 is several times
that, and any wrong face, frame, solid angle or weight changes the values by > 1e-2 relative.
"""

import math

import numpy as np
import pytest

from addon.engine.config import ProbesConfig
from addon.engine.methods.direct import face_planes
from addon.engine.passes import probe_capture, probe_lookup, probe_project, probe_relocate
from addon.engine.probe_grid import RELOCATE_CLEARANCE_RATIO, ProbeGrid, relocation_step

pytestmark = pytest.mark.gpu

RTOL = 1e-5
N = 8  # face texels


def textures(gl, grid: ProbeGrid):
    size = grid.atlas_size
    atlas = {p.name: gl.texture(size) for p in probe_capture.ATLAS}
    target = gl.target(list(atlas.values()), gl.depth_texture(size))
    return atlas, target


def mesh_of(gl, triangles):
    """The capture's mesh of `triangles` ((t, 3, 3) positions; normals from the winding), or None."""
    if triangles is None:
        return None
    tris = np.asarray(triangles, np.float32)
    normals = np.repeat(np.cross(tris[:, 1] - tris[:, 0], tris[:, 2] - tris[:, 0]), 3, axis=0)
    normals /= np.linalg.norm(normals, axis=-1, keepdims=True)
    attrs = {"pos_ws": tris.reshape(-1, 3), "plane_ws": np.repeat(face_planes(tris), 3, axis=0), "normal_ws": normals,
             "bounce_albedo": np.full((len(normals), 3), 0.5)}
    return gl.mesh(gl.program(probe_capture.SPEC), attrs, "triangles")


def capture(gl, grid, triangles=None):
    """The atlas G-buffer, moments, state and (zero) offsets of `grid` around `triangles` ((t, 3, 3)
    positions, or None: an empty world)."""
    atlas, target = textures(gl, grid)
    mesh = mesh_of(gl, triangles)
    probe_capture.run(gl, target, atlas, mesh, grid, probe_capture.face_matrices(grid, 100.0))
    moments, state, offset = gl.texture(grid.atlas_size), gl.texture(grid.state_size), probe_relocate.allocate(gl, grid)
    probe_capture.moments(gl, atlas, moments, state, grid, 1.0, offset)
    return atlas, moments, state, offset


def constant_sh(gl, grid, radiance_per_probe):
    """An SH table holding, for each probe, the exact L2 projection of a constant radiance (rgb):
    c_0 = L / Y00 = 2 sqrt(pi) L, the rest 0."""
    table = np.zeros((grid.sh_size[1], grid.sh_size[0], 4), np.float32)
    for p, radiance in enumerate(radiance_per_probe):
        ix, row = p % grid.dims[0], p // grid.dims[0]
        table[row, ix, :3] = np.asarray(radiance) * 2.0 * math.sqrt(math.pi)
    return gl.texture(grid.sh_size, data=table)


def test_constant_radiance_projects_to_exact_sh(gl):
    # Every texel of two probes sees a surface of albedo 0.5 lit with Diffuse Direct D = (1, 2, 4):
    # L = 0.5 D everywhere, so c_0 = 2 sqrt(pi) L (the texels' exact solid angles sum to 4 pi) and the other
    # eight coefficients are 0 by the cube's symmetry.
    grid = ProbeGrid(np.zeros(3), 1.0, (2, 1, 1), N)
    size = grid.atlas_size
    atlas = {"albedo": gl.texture(size, data=np.broadcast_to(np.float32([0.5, 0.5, 0.5, 1.0]), (size[1], size[0], 4)))}
    direct = gl.texture(size, data=np.broadcast_to(np.float32([1.0, 2.0, 4.0, 0.0]), (size[1], size[0], 4)))
    sh = gl.texture(grid.sh_size)
    probe_project.run(gl, atlas, direct, sh, grid)
    table = gl.read(sh)  # (rows ny nz, 9 nx, 4)
    radiance = np.array([0.5, 1.0, 2.0])
    for probe in range(2):
        coeffs = table[0, probe::2, :3]  # coefficient i of probe ix at column i nx + ix
        np.testing.assert_allclose(coeffs[0], 2.0 * math.sqrt(math.pi) * radiance, rtol=RTOL)
        assert np.abs(coeffs[1:]).max() <= RTOL * coeffs[0].max()


@pytest.mark.parametrize("encoding", ["sh", "irradiance"])
def test_one_probe_in_a_uniform_environment_gives_e_pi_l(gl, encoding):
    # A single probe whose every direction brings radiance L = (0.3, 0.6, 1.2), encoded by the GPU;
    # receivers anywhere around it, with any normal: E = pi L, so Diffuse Indirect = E / pi = L.
    # SH: exact to fp32 (the clamped cosine's band-0 factor pi times Y00 times c_0 = 2 sqrt(pi) L).
    # Irradiance maps: each normal's sum of max(0, n.w) dw over the 8^2-texel faces' centres is pi to
    # within 0.52 % (numpy: 1.0052 at a face centre, 0.9973 at a corner), so rtol 1e-2.
    grid = ProbeGrid(np.zeros(3), 1.0, (1, 1, 1), N)
    _, moments, state, offset = capture(gl, grid)  # an empty world: no occluder, every probe on
    size = grid.atlas_size
    albedo = gl.texture(size, data=np.broadcast_to(np.float32([1.0, 1.0, 1.0, 1.0]), (size[1], size[0], 4)))
    direct = gl.texture(size, data=np.broadcast_to(np.float32([0.3, 0.6, 1.2, 0.0]), (size[1], size[0], 4)))
    if encoding == "sh":
        light = gl.texture(grid.sh_size)
        probe_project.run(gl, {"albedo": albedo}, direct, light, grid)
    else:
        light = gl.texture(grid.tiled_size(probe_project.IRRADIANCE_TEXELS))
        probe_project.convolve(gl, {"albedo": albedo}, direct, light, grid)
    rng = np.random.default_rng(3)
    pos = np.c_[rng.uniform(-0.7, 0.7, (16, 3)), np.ones(16)].astype(np.float32).reshape(4, 4, 4)
    nrm = rng.normal(size=(16, 3))
    nrm = np.c_[nrm / np.linalg.norm(nrm, axis=1, keepdims=True), np.zeros(16)].astype(np.float32).reshape(4, 4, 4)
    out = gl.texture((4, 4))
    probe_lookup.run(gl, gl.texture((4, 4), data=pos), gl.texture((4, 4), data=nrm),
                     {encoding: light, "moments": moments, "state": state, "probe_offset": offset}, out, grid,
                     ProbesConfig())
    got = gl.read(out)[..., :3].reshape(-1, 3)
    rtol = RTOL if encoding == "sh" else 1e-2
    np.testing.assert_allclose(got, np.broadcast_to([0.3, 0.6, 1.2], got.shape), rtol=rtol)


WALL = [[[0.0, -3.0, -3.0], [0.0, 3.0, -3.0], [0.0, 3.0, 3.0]], [[0.0, -3.0, -3.0], [0.0, 3.0, 3.0], [0.0, -3.0, 3.0]]]


@pytest.mark.parametrize("wall", [False, True])
def test_a_wall_between_a_probe_and_a_receiver_gives_it_zero_weight(gl, wall):
    # Probes A at x = -0.5 (radiance 1 everywhere) and B at x = +0.5 (radiance 0); a receiver at
    # (0.25, 0, 0) with normal +z. Its lookup point moves normal_bias x spacing = 0.25 m up: trilinear
    # weights 0.25 (A) and 0.75 (B); the back-face terms are equal ((1 + 0) / 2)^2 + 0.2 = 0.45 (both
    # probes lie in the receiver's tangent plane). Without a wall: indirect = 0.25 x 1 exactly. With a wall
    # at x = 0, A sees it 0.53 m away towards the lookup point at 0.79 m: its visibility is exactly 0, and
    # the receiver reads B alone: 0.
    grid = ProbeGrid(np.array([-0.5, 0.0, 0.0]), 1.0, (2, 1, 1), N)
    _, moments, state, offset = capture(gl, grid, WALL if wall else None)
    sh = constant_sh(gl, grid, [(1.0, 1.0, 1.0), (0.0, 0.0, 0.0)])
    pos = gl.texture((1, 1), data=np.float32([[[0.25, 0.0, 0.0, 1.0]]]))
    nrm = gl.texture((1, 1), data=np.float32([[[0.0, 0.0, 1.0, 0.0]]]))
    out = gl.texture((1, 1))
    probe_lookup.run(gl, pos, nrm, {"sh": sh, "moments": moments, "state": state, "probe_offset": offset}, out,
                     grid, ProbesConfig())
    got = gl.read(out)[0, 0, :3]
    if wall:
        assert np.all(got == 0.0), got
    else:
        np.testing.assert_allclose(got, 0.25, rtol=RTOL)


def test_capture_sees_the_wall_at_its_distance(gl):
    # Probe A at x = -0.5 looks along +x (face 0) at the wall x = 0: its centre texels hold positions on the
    # wall at distance 0.5 / cos; the moments' mean over a 3 x 3 window is within the window's spread.
    grid = ProbeGrid(np.array([-0.5, 0.0, 0.0]), 1.0, (2, 1, 1), N)
    atlas, moments, _, _ = capture(gl, grid, WALL)
    x, y = grid.face_origin(0, 0)
    pos = gl.read(atlas["position"])[y:y + N, x:x + N]
    assert np.all(pos[..., 3] == 1.0) and np.allclose(pos[..., 0], 0.0, atol=1e-6)
    mean = gl.read(moments)[y + N // 2, x + N // 2, 0]
    assert 0.5 <= mean <= 0.5 / math.cos(math.atan(1.5 * 2.0 / N * math.sqrt(2.0)))


def _box_faces(lo, hi):
    """The 12 triangles of an axis-aligned box (normals from the winding; the method is two-sided)."""
    lo, hi = np.asarray(lo, np.float64), np.asarray(hi, np.float64)
    c = np.array([[x, y, z] for z in (lo[2], hi[2]) for y in (lo[1], hi[1]) for x in (lo[0], hi[0])])
    quads = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
    tris = []
    for a, b, e, d in quads:  # two triangles per planar quad a-b-e-d
        tris += [[c[a], c[b], c[e]], [c[a], c[e], c[d]]]
    return np.array(tris)


def test_closed_box_keeps_its_flux_over_bounces(gl):
    # A closed box [-1, 1]^3 of albedo 0.5 with a 100 W point light inside: every bounce's light lands on
    # the box again, so the indirect irradiance integrated over its 24 m^2 after N bounces is exactly
    # P (rho + ... + rho^N) = 50, 75, 87.5 W. Each camera looks at one face from the centre (90 degrees),
    # so the integral is 4 m^2 x sum over the faces of pi x mean(Diffuse Indirect). Measured (the
    # defaults, 16 probes a side): 1.005, 1.006, 1.006 x exact (the first bounce over-reads by 0.5 %: L2
    # SH and the probes' interpolation; later bounces add no more than that share; without the deringing
    # window 1.019, 1.021, 1.022); bound 1 +- 0.03.
    from addon.engine import methods
    from addon.engine.config import GIConfig, RsmConfig
    from addon.engine.scene import Camera, Light, Scene
    from addon.engine.transforms import look_along, perspective

    tris = _box_faces([-1, -1, -1], [1, 1, 1])
    n = np.cross(tris[:, 1] - tris[:, 0], tris[:, 2] - tris[:, 0])
    normals = np.repeat((n / np.linalg.norm(n, axis=1, keepdims=True))[:, None], 3, axis=1)

    def camera(axis):
        up = (1.0, 0.0, 0.0) if abs(axis[2]) > 0.5 else (0.0, 0.0, 1.0)
        view = look_along(np.zeros(3), np.asarray(axis, np.float64), np.asarray(up, np.float64))
        return Camera(view, perspective(np.radians(90.0), 1e-3, 10.0), 48, 48)

    axes = np.concatenate([np.eye(3), -np.eye(3)])
    power, rho = 100.0, 0.5
    for bounces in (1, 2, 3):
        light = Light("POINT", [0.2, -0.1, 0.3], [0, 0, -1], [1, 1, 1], power_w=power)
        scene = Scene(tris.astype(np.float32), normals.astype(np.float32), np.full((len(tris), 3), rho, np.float32),
                      np.zeros((len(tris), 3), np.float32), lights=[light], camera=camera(axes[0]))
        gi = GIConfig(method="probes", bounces=bounces)
        method = methods.create(gl, {"gi": gi, "rsm": RsmConfig(resolution=128)})
        method.set_scene(scene)
        flux = 0.0
        for axis in axes:
            method.set_camera(camera(axis))
            images = method.run().images
            assert (images["albedo"][..., 3] == 1).all()
            flux += 4.0 * math.pi * images["indirect"][..., :3].mean()
        exact = power * sum(rho**k for k in range(1, bounces + 1))
        assert flux == pytest.approx(exact, rel=0.03), (bounces, flux / exact)


def test_only_the_probes_a_lookup_reads_are_lit_and_the_image_is_the_same(gl):
    # ProbesConfig.only_read_probes captures and lights only the corners of cells within the normal bias
    # of a triangle (ProbeGrid.read_by): the lookups (the camera's, and at 2 bounces the atlas's) never
    # weigh any other probe, so the images are the same to the bit. In a closed 2 m box with a 0.4 m
    # block at 16 probes a side, the middle of the room reads none: fewer than 3 in 4 probes are lit.
    from addon.engine import methods
    from addon.engine.config import GIConfig, RsmConfig
    from addon.engine.scene import Camera, Light, Scene
    from addon.engine.transforms import look_along, perspective

    tris = np.concatenate([_box_faces([-1, -1, -1], [1, 1, 1]), _box_faces([-0.6, -0.6, -1], [-0.2, -0.2, -0.6])])
    n = np.cross(tris[:, 1] - tris[:, 0], tris[:, 2] - tris[:, 0])
    normals = np.repeat((n / np.linalg.norm(n, axis=1, keepdims=True))[:, None], 3, axis=1)
    view = look_along(np.array([0.0, 0.9, 0.0]), np.array([0.0, -1.0, -0.3]), np.array([0.0, 0.0, 1.0]))
    scene = Scene(tris.astype(np.float32), normals.astype(np.float32), np.full((len(tris), 3), 0.6, np.float32),
                  np.zeros((len(tris), 3), np.float32),
                  lights=[Light("POINT", [0.2, -0.1, 0.7], [0, 0, -1], [1, 1, 1], power_w=100.0)],
                  camera=Camera(view, perspective(np.radians(70.0), 1e-3, 10.0), 48, 48))
    images, work = [], []
    for only_read in (True, False):
        method = methods.create(gl, {"gi": GIConfig(method="probes", bounces=2), "rsm": RsmConfig(resolution=64),
                                     "probes": ProbesConfig(only_read_probes=only_read)})
        method.set_scene(scene)
        images.append(method.run().images["indirect"])
        work.append(method.work())
    assert images[0].mean() > 0 and np.array_equal(images[0], images[1])
    assert work[1] == {"probes": 4096, "probes_lit": 4096, "probes_moved": 0} and work[0]["probes_lit"] < 0.75 * 4096


# Relocation (probe_relocate; the numpy twin probe_grid.relocation_step, tested in tests/unit).
FLOOR_AT = -0.01  # a floor 1 cm under the probes of the grids below (spacing 1 m)


def _floor(z):
    return [[[-5.0, -5.0, z], [5.0, -5.0, z], [5.0, 5.0, z]], [[-5.0, -5.0, z], [5.0, 5.0, z], [-5.0, 5.0, z]]]


def _per_probe(image, grid, p):
    """(6, n, n, 4) the atlas texels of probe p, [face, row j, column i] (the capture order)."""
    n = grid.face_texels
    return np.stack([image[y:y + n, x:x + n] for x, y in (grid.face_origin(p, f) for f in range(6))])


def test_relocation_step_equals_the_numpy_twin(gl):
    # Probes on a 3 x 2 x 1 grid 1 cm above a floor, the floor the bounds' bottom; probe 4 (x = 0, y = 1)
    # sits inside a solid box [-0.2, 0.2] x [0.8, 1.2] x [-0.005, 0.05] (outward normals) on it. The GPU
    # step gives what probe_grid.relocation_step gives on the same capture read back: the 1 cm probes rise
    # to the clearance; probe 4 leaves through the box's top (its bottom, nearer, would end below the
    # bounds). fp32 positions of order 1 m against float64:
    # 1e-5 m (the decisions are far from their thresholds here, so they agree).
    grid = ProbeGrid(np.array([-1.0, 0.0, 0.0]), 1.0, (3, 2, 1), N)
    box = _box_faces((-0.2, 0.8, -0.005), (0.2, 1.2, 0.05))[:, ::-1]  # reversed winding: outward normals
    atlas, target = textures(gl, grid)
    probe_capture.run(gl, target, atlas, mesh_of(gl, np.concatenate([_floor(FLOOR_AT), box])), grid,
                      probe_capture.face_matrices(grid, 100.0))
    offset = probe_relocate.allocate(gl, grid)
    bounds = (np.array([-1.5, -0.5, FLOOR_AT]), np.array([1.5, 1.5, 0.5]))
    got, moved = probe_relocate.step(gl, atlas, offset, grid, bounds)
    position, normal = gl.read(atlas["position"]), gl.read(atlas["normal"])
    for p, grid_pos in enumerate(grid.positions_m()):
        pos, nrm = _per_probe(position, grid, p), _per_probe(normal, grid, p)
        want = relocation_step(grid_pos, np.zeros(3), pos[..., :3], nrm[..., :3], nrm[..., 3], pos[..., 3] > 0,
                               1.0, *bounds)
        np.testing.assert_allclose(got[p], want, rtol=0, atol=1e-5, err_msg=f"probe {p}")
        assert moved[p]
    np.testing.assert_allclose(got[4], [0.0, 0.0, 0.05 + RELOCATE_CLEARANCE_RATIO], atol=1e-5)
    np.testing.assert_allclose(got[0], [0.0, 0.0, RELOCATE_CLEARANCE_RATIO + FLOOR_AT], atol=1e-5)


def test_a_relocated_probe_is_captured_again_where_it_moved(gl):
    # One probe 1 cm above a floor: the step moves it to the clearance above it (0.15 m: offset 0.14,
    # fp32 to 1e-6), its tile is cleared and drawn again from there, and a second step finds it in place
    # (no move). From its new position its -z face sees the floor at z = -0.01 in every texel, the
    # centre texels at between 0.15 m and 0.15 / cos(their angle off the axis) m (fp32: 1e-6 m either side).
    grid = ProbeGrid(np.zeros(3), 1.0, (1, 1, 1), N)
    atlas, target = textures(gl, grid)
    mesh = mesh_of(gl, _floor(FLOOR_AT))
    probe_capture.run(gl, target, atlas, mesh, grid, probe_capture.face_matrices(grid, 100.0))
    offset = probe_relocate.allocate(gl, grid)
    bounds = (np.full(3, -1.0), np.full(3, 1.0))
    offsets_m, moved = probe_relocate.step(gl, atlas, offset, grid, bounds)
    assert moved[0]
    np.testing.assert_allclose(offsets_m[0], [0.0, 0.0, RELOCATE_CLEARANCE_RATIO + FLOOR_AT], rtol=0, atol=1e-6)
    probe_relocate.clear_moved(gl, atlas, offset, grid)
    positions = grid.positions_m() + offsets_m
    probe_capture.draw(gl, target, mesh, grid, probe_capture.face_matrices(grid, 100.0, positions), moved, positions)
    again, moved_again = probe_relocate.step(gl, atlas, offset, grid, bounds)
    assert not moved_again[0] and np.array_equal(again, offsets_m)
    down = _per_probe(gl.read(atlas["position"]), grid, 0)[5]  # face 5 looks along -z
    assert np.all(down[..., 3] == 1.0) and np.allclose(down[..., 2], FLOOR_AT, atol=1e-6)
    centre = np.linalg.norm(down[N // 2 - 1:N // 2 + 1, N // 2 - 1:N // 2 + 1, :3] - positions[0], axis=-1)
    clearance = RELOCATE_CLEARANCE_RATIO
    assert np.all(centre >= clearance - 1e-6)
    assert np.all(centre <= clearance / math.cos(math.atan(math.sqrt(2) / N)) + 1e-6)


def test_the_capture_keeps_positions_on_their_triangles_plane(gl):
    # A probe 1 mm above a 4 m floor at z = 0.37 sees it at grazing angles towards its faces' edges,
    # where the rasterizer's interpolation left positions up to 4e-4 of their distance off the plane
    # (the emissive scene's panel, measured), enough for a glowing floor to light itself
    # (common/polygon.glsl); here up to 21 ulps (measured). Put back on the plane (common/face_plane.glsl)
    # each lies within 2 ulps of the floor's fp32 height, the rounding of the projection itself.
    z = np.float32(0.37)
    grid = ProbeGrid(np.array([0.0, 0.0, float(z) + 1e-3]), 1.0, (1, 1, 1), N)
    a, b, c, d = [(-2, -2, z), (2, -2, z), (2, 2, z), (-2, 2, z)]
    atlas, _, _, _ = capture(gl, grid, [[a, b, c], [a, c, d]])
    pos = gl.read(atlas["position"])
    seen = pos[..., 3] == 1.0
    assert seen.sum() >= 2 * N * N  # the lower halves of the four side faces (the face below: within its near plane)
    assert np.abs(pos[seen][:, 2] - z).max() <= 2 * np.spacing(z)


def test_the_probes_see_the_skys_light_through_an_opening(gl):
    # A uniform sky of radiance L over a closed room whose roof has a 0.6 m opening: a floor point gets
    # E / pi = L x (the opening's cosine-weighted solid angle) / pi (area_light.polygon_irradiance,
    # exact). The surfaces the probes see are lit by the sky pass (ProbesConfig.atlas_sky_directions),
    # whose error shrinks with its directions: over the atlas's floor texels (8 probes a side), per-texel
    # rel_rmse / mean over the exact mean 1.65 / 1.40 at 16 directions, 0.56 / 1.016 at 64, 0.162 / 1.043
    # at 256 (each direction's shadow is the opening's image softened by its region's width; their sum
    # converges). Bounds at 256: 0.2 and 1 +- 0.06. The world as 16 suns, one shadow map and direct pass
    # each, as the atlas was lit before: 1.09 / 1.94.
    import sys
    from dataclasses import replace
    from pathlib import Path

    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "hard"))
    from hard_scenes import camera, room_with_a_roof_opening
    from hard_scenes import scene as make_scene

    from addon.engine import methods
    from addon.engine.area_light import polygon_irradiance
    from addon.engine.config import GIConfig, RsmConfig
    from addon.engine.world import constant_map

    radiance = 2.0
    geometry, outline = room_with_a_roof_opening(0.6)
    sc = replace(make_scene(geometry, [], camera([0, -0.9, 1.0], [0, 1, -0.5], size=16)),
                 world_map=constant_map(np.full(3, radiance, np.float32)))
    method = methods.create(gl, {"gi": GIConfig(method="probes"), "rsm": RsmConfig(resolution=64),
                                 "probes": ProbesConfig(probes_per_side=8, atlas_sky_directions=256)})
    method.set_scene(sc)
    method.run()
    position = gl.read(method.atlas["position"])
    world_m = position[..., :3] + method.origin_m  # the atlas holds the uploaded (re-centred) frame
    floor = (position[..., 3] > 0) & (np.abs(world_m[..., 2]) < 1e-4) & np.all(np.abs(world_m[..., :2]) < 0.9, axis=-1)
    up = np.array([0.0, 0.0, 1.0])
    exact = np.array([radiance * polygon_irradiance(p, up, outline) / math.pi for p in world_m[floor]])
    ours = gl.read(method.atlas_direct)[..., :3][floor]
    assert floor.sum() > 1000 and np.isfinite(ours).all() and ours.min() >= 0.0
    assert np.sqrt(np.mean((ours - exact[:, None]) ** 2)) / exact.mean() < 0.2
    assert ours.mean() / exact.mean() == pytest.approx(1.0, abs=0.06)


def _spot_lit_floor_probes(gl, area_samples):
    """A closed 4 x 4 x 2 m room (albedo 0.5) lit only by a spot 1 m above the floor's centre pointing
    down with a sharp 60-degree cone (a disc of radius tan(30 deg) m on the floor); probes 16 a side, so
    the lowest layer is 0.125 m above the floor. Returns (the probes' positions (m, world), int L dw over each
    probe's first-bounce capture: the SH table's c_0 x 2 sqrt(pi)), and the exact answer's inputs."""
    import sys
    from pathlib import Path

    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "hard"))
    from hard_scenes import box, camera
    from hard_scenes import scene as make_scene

    from addon.engine import methods
    from addon.engine.config import GIConfig, RsmConfig
    from addon.engine.scene import Light

    tris, normals = box([-2, -2, 0], [2, 2, 2])
    geometry = (tris, normals, np.full((len(tris), 3), 0.5))
    spot = Light("SPOT", [0.0, 0.0, 1.0], [0.0, 0.0, -1.0], [1.0, 1.0, 1.0], power_w=100.0,
                 spot_size_rad=math.radians(60.0), spot_blend=0.0)
    sc = make_scene(geometry, [spot], camera([0, -1.9, 1.0], [0, 1, -0.3], size=16))
    method = methods.create(gl, {"gi": GIConfig(method="probes"), "rsm": RsmConfig(resolution=256),
                                 "probes": ProbesConfig(probes_per_side=16, area_samples=area_samples)})
    method.set_scene(sc)
    method.run()
    grid = method.grid
    table = gl.read(method.light)  # c_0 of probe p = ix + nx row at texel (ix, row)
    c0 = table[:, :grid.dims[0], :3].reshape(-1, 3).mean(axis=-1)
    return grid.positions_m() + method.origin_m, c0 * 2.0 * math.sqrt(math.pi)


def _exact_spot_disc_radiance_integral(probe_m):
    """int L dw over the lit disc seen from probe_m: L = albedo E / pi, E = I cos / d^2 with I = P / (4 pi)
    (scene.Light), summed over 2 mm cells of the floor (the disc's edge cells split by their centres:
    ~0.3 % of its area)."""
    intensity, albedo, height = 100.0 / (4.0 * math.pi), 0.5, 1.0
    radius = math.tan(math.radians(30.0))
    cell = 0.002
    x = np.arange(-radius, radius, cell) + cell / 2
    gx, gy = np.meshgrid(x, x)
    inside = gx ** 2 + gy ** 2 <= radius ** 2
    gx, gy = gx[inside], gy[inside]
    d2 = gx ** 2 + gy ** 2 + height ** 2
    radiance = albedo * intensity * height / d2 ** 1.5 / math.pi
    r2 = (gx - probe_m[0]) ** 2 + (gy - probe_m[1]) ** 2 + probe_m[2] ** 2
    solid_angle = cell * cell * probe_m[2] / r2 ** 1.5  # the cell's area x its cosine towards the probe / r^2
    return float(np.sum(radiance * solid_angle))


def test_area_samples_integrate_a_lit_disc_seen_at_a_grazing_angle(gl):
    # The probes of the lowest layer, 0.125 m above the floor and 1.1-1.9 m from the spot's axis, see its
    # lit disc 2-13 degrees below their horizon, within the 14-degree texel row next to it of an 8^2 face.
    # Shaded at texel centres, a probe's rows hit or miss it (docs/PROBES.md, "The capture aliases bright
    # light seen at a grazing angle"): int L dw over the capture against the exact, rel_rmse over those
    # 120 probes 1.74 (some read 0, others 3x). Shaded at 8 points along each grazing texel's footprint:
    # 0.069, at 16 points 0.041 (what is left: the disc's sides fall between the face's columns, which
    # are still shaded at their centres). Bounds: the centre-only error above 0.4, the area-sampled one
    # below 0.15.
    errors = {}
    for samples in (1, 8):
        positions, ours = _spot_lit_floor_probes(gl, samples)
        rho = np.hypot(positions[:, 0], positions[:, 1])
        chosen = (np.abs(positions[:, 2] - 0.125) < 1e-6) & (rho > 1.1) & (rho < 1.9)
        exact = np.array([_exact_spot_disc_radiance_integral(p) for p in positions[chosen]])
        assert chosen.sum() >= 20 and np.isfinite(ours).all() and ours.min() >= 0.0
        errors[samples] = float(np.sqrt(np.mean((ours[chosen] - exact) ** 2)) / exact.mean())
    assert errors[1] > 0.4, errors
    assert errors[8] < 0.15, errors
