"""Method `direct` against closed-form irradiance: a 2 x 2 m floor, a 0.4 m occluder 1 m above it,
and each light kind 2 m above the floor centre.

Exact answers (Diffuse Direct unit = E / pi): a point/spot of P W has I = P / (4 pi) W/sr, so a floor
point at offset (x, y) gets E = I cos / r^2 with r^2 = x^2 + y^2 + 4, cos = 2 / r; a sun gives
E = strength. Pixels are sampled at their centre, whose world position the test computes from the
G-buffer's own inverse mapping, so the only error is fp32 arithmetic (1e-4 relative).
"""

import numpy as np
import pytest

from addon.engine.area_light import polygon_irradiance
from addon.engine.config import GIConfig, RsmConfig
from addon.engine.methods.direct import DirectMethod
from addon.engine.scene import AlbedoTextures, Camera, Light, Scene
from addon.engine.transforms import look_along, perspective

pytestmark = pytest.mark.gpu
SIZE = 64
H = 2.0


def quad(x0, x1, y0, y1, z):
    p = np.array([[x0, y0, z], [x1, y0, z], [x1, y1, z], [x0, y1, z]])
    return [[p[0], p[1], p[2]], [p[0], p[2], p[3]]]


def make_scene(light):
    tris = np.array(quad(-1, 1, -1, 1, 0.0) + quad(0.3, 0.7, 0.3, 0.7, 1.0), np.float32)
    normals = np.zeros_like(tris)
    normals[..., 2] = 1.0
    cam = Camera(look_along([0, 0, 5], [0, 0, -1], [0, 1, 0]), perspective(np.radians(30), 0.1, 100), SIZE, SIZE)
    return Scene(tris, normals, np.full((4, 3), 0.8, np.float32), np.zeros((4, 3), np.float32), [light], camera=cam)


def pixel_of(cam, p):
    clip = cam.view_projection @ np.append(p, 1.0)
    ndc = clip[:2] / clip[3]
    col = int((ndc[0] * 0.5 + 0.5) * cam.width)
    row = cam.height - 1 - int((ndc[1] * 0.5 + 0.5) * cam.height)
    return row, col


def floor_point_at_pixel(cam, row, col):
    """World point on z = 0 seen through the centre of pixel (row from top, col)."""
    ndc = np.array([(col + 0.5) / cam.width * 2 - 1, ((cam.height - 1 - row) + 0.5) / cam.height * 2 - 1])
    inv = np.linalg.inv(cam.view_projection)
    a = inv @ np.array([*ndc, -1.0, 1.0])
    b = inv @ np.array([*ndc, 1.0, 1.0])
    a, b = a[:3] / a[3], b[:3] / b[3]
    t = a[2] / (a[2] - b[2])
    return a + t * (b - a)


def render(light, gl):
    method = DirectMethod(gl, GIConfig(), RsmConfig(resolution=512))
    scene = make_scene(light)
    method.set_scene(scene)
    return scene.camera, method.run().images["direct"][..., 0]


def point_irradiance_over_pi(intensity, p):
    d = np.array([0, 0, H]) - p
    r2 = d @ d
    return intensity * (d[2] / np.sqrt(r2)) / r2 / np.pi


@pytest.mark.parametrize("kind", ["POINT", "SPOT"])
def test_point_and_spot_inside_the_cone(gl, kind):
    light = Light(kind, [0, 0, H], [0, 0, -1], [1, 1, 1], power_w=300.0, spot_size_rad=np.radians(70),
                  spot_blend=0.15)
    cam, img = render(light, gl)
    for world in ([0.0, 0.0, 0.0], [-0.3, 0.2, 0.0], [0.2, -0.4, 0.0]):
        row, col = pixel_of(cam, np.array(world))
        p = floor_point_at_pixel(cam, row, col)
        expected = point_irradiance_over_pi(300.0 / (4 * np.pi), p)
        assert img[row, col] == pytest.approx(expected, rel=1e-4)


def test_spot_cone_edge_follows_cycles_smoothstep(gl):
    light = Light("SPOT", [0, 0, H], [0, 0, -1], [1, 1, 1], power_w=300.0, spot_size_rad=np.radians(70),
                  spot_blend=0.15)
    cam, img = render(light, gl)
    cos_half = np.cos(np.radians(35))
    for x in (-0.95, -0.9, -0.75):  # points spanning the blend zone and beyond the cone along -x
        row, col = pixel_of(cam, np.array([x, 0.0, 0.0]))
        p = floor_point_at_pixel(cam, row, col)
        w = p - np.array([0, 0, H])
        cos_t = -w[2] / np.linalg.norm(w)
        t = np.clip((cos_t - cos_half) / ((1 - cos_half) * 0.15), 0, 1)
        mask = t * t * (3 - 2 * t)
        assert img[row, col] == pytest.approx(mask * point_irradiance_over_pi(300.0 / (4 * np.pi), p), rel=1e-3,
                                              abs=1e-6)


@pytest.mark.parametrize("kind", ["POINT", "SPOT", "SUN"])
def test_occluder_casts_a_shadow(gl, kind):
    # The floor point (0.95, 0.95) sees the light through the occluder (0.3..0.7 at z = 1): the point
    # light's ray crosses z = 1 at 0.475, the tilted sun's (direction ~ (0.4, 0.4, -1)) at 0.55. The
    # camera's ray crosses z = 1 at 0.76, so the camera sees the floor there, not the occluder.
    light = Light(kind, [0, 0, H], [0.4, 0.4, -1.0] if kind == "SUN" else [0, 0, -1], [1, 1, 1], power_w=300.0,
                  spot_size_rad=np.radians(120), spot_blend=0.0, sun_strength=3.0)
    cam, img = render(light, gl)
    row, col = pixel_of(cam, np.array([0.95, 0.95, 0.0]))
    assert img[row, col] == 0.0
    row, col = pixel_of(cam, np.array([0.2, -0.3, 0.0]))  # in the open: lit
    assert img[row, col] > 0.1


def shadow_edge_errors(gl, light, shadow_square, rsm_texels, sun_shadow_texels, away_m):
    """Floor pixels farther than away_m from the exact edge of `light`'s hard shadow whose visibility is
    not exactly 0 or 1 (1e-4 of the lit value: fp32). The occluder 0.3..0.7 at z = 1 shadows the floor
    in `shadow_square` (x0, x1, y0, y1); pixels whose camera ray meets the occluder are skipped."""
    method = DirectMethod(gl, GIConfig(), RsmConfig(resolution=rsm_texels, sun_shadow_texels=sun_shadow_texels))
    scene = make_scene(light)
    method.set_scene(scene)
    img = method.run().images["direct"][..., 0]
    x0, x1, y0, y1 = shadow_square
    wrong = 0
    for row in range(SIZE):
        for col in range(SIZE):
            p = floor_point_at_pixel(scene.camera, row, col)
            seen_at_occluder = 0.8 * p[:2]
            if max(abs(p[0]), abs(p[1])) > 0.98 or np.all((0.3 <= seen_at_occluder) & (seen_at_occluder <= 0.7)):
                continue
            if light.kind == "SUN":
                lit_value = 3.0 * -light.direction[2] / np.pi  # E cos / pi (Light normalises its direction)
            else:
                lit_value = point_irradiance_over_pi(light.power_w / (4 * np.pi), p)
            inside = x0 <= p[0] <= x1 and y0 <= p[1] <= y1
            edge_m = min(p[0] - x0, x1 - p[0], p[1] - y0, y1 - p[1]) if inside else \
                np.hypot(max(x0 - p[0], 0.0, p[0] - x1), max(y0 - p[1], 0.0, p[1] - y1))
            want = 0.0 if inside else lit_value
            wrong += edge_m > away_m and abs(img[row, col] - want) > 1e-4 * lit_value
    return wrong


def test_a_hard_sun_shadow_is_exact_from_a_coarse_map(gl):
    # The sun shines along (0.23, 0.31, -1): the occluder 0.3..0.7 at z = 1 shadows the floor where x lies
    # in [0.3, 0.7] + 0.23 and y in [0.3, 0.7] + 0.31. The exact test (the triangles the map names) puts
    # the edge where the geometry does: with a 16-texel map (12.5 cm texels) and no map of its own, no
    # pixel farther than 0.1 mm from it is wrong. Without it, 10 pixels farther than 5 mm were, and a
    # 512-texel map of its own (5 mm texels) was needed for none to be.
    sun = Light("SUN", [0, 0, H], [0.23, 0.31, -1.0], [1, 1, 1], sun_strength=3.0)
    assert shadow_edge_errors(gl, sun, (0.53, 0.93, 0.61, 1.01), 16, 0, away_m=1e-4) == 0


def test_a_soft_sun_shadow_is_exact_beyond_its_penumbra_from_a_coarse_map(gl):
    # A sun 2 degrees wide along (0.23, 0.31, -1) (1.08 m of its rays between the occluder and the floor):
    # its penumbra reaches tan(1 degree) x 1.08 m / cos 21 degrees = 2 cm either side of the hard
    # edge. Beyond 3 cm the floor is exactly lit or exactly dark, with a 16-texel map (12.5 cm texels)
    # and no map of its own; the classic filter of that map got 14 pixels wrong.
    sun = Light("SUN", [0, 0, H], [0.23, 0.31, -1.0], [1, 1, 1], sun_strength=3.0, sun_angle_rad=np.radians(2.0))
    assert shadow_edge_errors(gl, sun, (0.53, 0.93, 0.61, 1.01), 16, 0, away_m=0.03) == 0


def test_a_blocker_seen_only_through_a_slit_narrower_than_a_texel_still_shadows(gl):
    # A sun straight down; a roof at z = 1 over the whole floor but for a 2 mm slit x in [0, 0.002]; under
    # the slit a plate at z = 0.5 (|x|, |y| <= 0.2). No texel of a 16-texel map sees through the slit (its
    # centres lie at x = +-0.0625, ...), so the map names the roof only, which the floor's ray under the
    # slit does not cross: the plate, which it does cross, is hidden. Exact answer under the slit and the
    # plate: 0. The camera, under the roof at z = 0.4, puts a pixel centre on that floor point.
    floor = quad(-1, 1, -1, 1, 0.0)
    roof = quad(-1, 0.0, -1, 1, 1.0) + quad(0.002, 1, -1, 1, 1.0)
    plate = quad(-0.2, 0.2, -0.2, 0.2, 0.5)
    tris = np.array(floor + roof + plate, np.float32)
    normals = np.zeros_like(tris)
    normals[..., 2] = 1.0
    target = np.array([0.001, 0.0, 0.0])
    half_pixel_m = np.tan(np.radians(15)) * 0.4 / SIZE  # the camera's pixel centres beside its axis
    cam = Camera(look_along([target[0] - half_pixel_m, -half_pixel_m, 0.4], [0, 0, -1], [0, 1, 0]),
                 perspective(np.radians(30), 0.1, 100), SIZE, SIZE)
    sun = Light("SUN", [0, 0, H], [0.0, 0.0, -1.0], [1, 1, 1], sun_strength=3.0)
    scene = Scene(tris, normals, np.full((len(tris), 3), 0.8, np.float32), np.zeros((len(tris), 3), np.float32),
                  [sun], camera=cam)
    method = DirectMethod(gl, GIConfig(), RsmConfig(resolution=16, sun_shadow_texels=0))
    method.set_scene(scene)
    img = method.run().images["direct"][..., 0]
    row, col = pixel_of(cam, target)
    p = floor_point_at_pixel(cam, row, col)
    assert 0.0 < p[0] < 0.002 and abs(p[1]) < 0.2  # the pixel's floor point lies under the slit and the plate
    assert img[row, col] == 0.0
    row, col = pixel_of(cam, np.array([-0.05, 0.05, 0.0]))  # under the roof: dark too
    assert img[row, col] == 0.0


@pytest.mark.parametrize("kind", ["POINT", "SPOT"])
def test_a_lamps_hard_shadow_is_exact_from_a_coarse_map(gl, kind):
    # A lamp at (0, 0, 2) shadows through the occluder at z = 1 the floor square [0.6, 1.4]^2, cut by the
    # floor's edge at 1 (x2 from the lamp's foot: similar triangles). A 16-texel RSM's texels are 12.5 cm
    # wide there; no pixel farther than 0.1 mm from the exact edge may be wrong (a test against the
    # nearest texel's depth got 8 wrong for the point light, 16 for the spot).
    light = Light(kind, [0, 0, H], [0, 0, -1], [1, 1, 1], power_w=300.0, spot_size_rad=np.radians(120),
                  spot_blend=0.0)
    assert shadow_edge_errors(gl, light, (0.6, 1.4, 0.6, 1.4), 16, 0, away_m=1e-4) == 0


@pytest.mark.parametrize("shape, sx, sy", [("SQUARE", 1.0, 1.0), ("DISK", 1.2, 1.2), ("RECTANGLE", 1.6, 0.4)])
def test_area_light_gives_its_polygons_irradiance(gl, shape, sx, sy):
    # Exact answer: the numpy twin (area_light.polygon_irradiance, itself checked against closed forms
    # and quadrature) summed over the light's patches at the pixel's own world point, radiance
    # P / (pi A); points the occluder shadows from no patch centre. fp32 GPU arithmetic: 1e-4.
    from addon.engine.area_light import split_area_light

    light = Light("AREA", [0, 0, H], [0, 0, -1], [1, 1, 1], power_w=300.0, area_shape=shape, size_x_m=sx,
                  size_y_m=sy, axis_x=[1, 0, 0])
    cam, img = render(light, gl)
    patches = split_area_light(light, RsmConfig().area_patches)
    for world in ([0.0, -0.6, 0.0], [-0.5, 0.2, 0.0], [-0.9, -0.9, 0.0]):
        row, col = pixel_of(cam, np.array(world))
        p = floor_point_at_pixel(cam, row, col)
        e = sum(r[0] * polygon_irradiance(p, np.array([0.0, 0.0, 1.0]), v[:c]) for pt in patches
                for v, c, r in zip(pt.emitter.vertices, pt.emitter.counts, pt.emitter.radiance, strict=True))
        assert img[row, col] == pytest.approx(e / np.pi, rel=1e-4)


def test_uniform_world_over_an_open_plane_gives_its_radiance(gl):
    # A uniform world of radiance L: a surface that sees the whole sky gets E = pi L (Diffuse Direct = L).
    # The world's suns sum to pi L exactly on an upward normal (world.py); the occluder's shadow is
    # away from the tested point (its 0.3-0.7 square casts no shadow on (-0.7, -0.7) for any sun with
    # a direction above 35 degrees; lower suns shadow a few percent of the sky there, hence rtol 3e-2).
    floor = np.array(quad(-1, 1, -1, 1, 0.0), np.float32)
    cam = make_scene(Light("POINT", [0, 0, 2], [0, 0, -1], [1, 1, 1])).camera
    scene = Scene(floor, np.tile([0, 0, 1], (2, 3, 1)).astype(np.float32), np.full((2, 3), 0.8, np.float32),
                  np.zeros((2, 3), np.float32), [], world_color=np.array([0.5, 1.0, 2.0], np.float32), camera=cam)
    method = DirectMethod(gl, GIConfig(), RsmConfig(resolution=256))
    method.set_scene(scene)
    img = method.run().images["direct"]
    row, col = pixel_of(cam, np.array([-0.7, -0.7, 0.0]))
    np.testing.assert_allclose(img[row, col, :3], [0.5, 1.0, 2.0], rtol=1e-4)


def test_sun_irradiance(gl):
    light = Light("SUN", [0, 0, 10], [0, 0, -1], [1.0, 0.5, 0.25], sun_strength=3.0)
    method = DirectMethod(gl, GIConfig(), RsmConfig(resolution=256))
    scene = make_scene(light)
    method.set_scene(scene)
    img = method.run().images["direct"]
    row, col = pixel_of(scene.camera, np.array([-0.5, -0.5, 0.0]))
    np.testing.assert_allclose(img[row, col, :3], np.array([1.0, 0.5, 0.25]) * 3.0 / np.pi, rtol=1e-5)


def test_empty_scene_and_no_lights_give_zero(gl):
    cam = Camera(look_along([0, 0, 5], [0, 0, -1], [0, 1, 0]), perspective(np.radians(30), 0.1, 100), 16, 16)
    for scene in (Scene(camera=cam), Scene(**{**make_scene(None).__dict__, "lights": []})):
        method = DirectMethod(gl, GIConfig(), RsmConfig(resolution=64))
        method.set_scene(scene)
        img = method.run().images["direct"]
        assert np.all(img[..., :3] == 0.0)


def test_every_update_starts_from_a_cleared_gbuffer(gl):
    """The G-buffer's colours are zeroed by a compute pass and its depth alone by a clear. If depth were
    not cleared, the second update's fragments (same depth, depth test LESS) would all fail and the
    image go black; if the colours were not, what a moved camera no longer sees would stay. Exact: the
    second and third updates equal the first bit for bit, and a camera looking away sees nothing (w = 0)."""
    method = DirectMethod(gl, GIConfig(), RsmConfig(resolution=64))
    scene = make_scene(Light("SUN", [0, 0, 0], [0, 0, -1], [1, 1, 1], sun_strength=2.0))
    method.set_scene(scene)
    first = method.run().images["direct"]
    assert first[..., 0].max() > 0
    for _ in range(2):
        np.testing.assert_array_equal(method.run().images["direct"], first)
    # The camera turned to look up (same size: the G-buffer is kept): no pixel sees geometry now.
    up = Camera(look_along([0, 0, 5], [0, 0, 1], [0, 1, 0]), scene.camera.projection, SIZE, SIZE)
    method.set_camera(up)
    method.run()
    assert np.all(method.backend.read(method.gbuf["position"])[..., 3] == 0.0)


def test_first_face_replaces_what_the_texture_holds(gl):
    """accumulate=False (the probes' first light face of a solve): every pixel that sees geometry gets
    that face's light in place of what `direct` held, so the faces after it, added, give exactly the
    image of a zeroed texture with every face added (the same sums in the same order: bit for bit);
    pixels that see nothing are not written. A point light among the geometry (between the floor and the
    occluder: one outside the scene's bounds gets fewer views, light_views): six faces, each shading the
    pixels it owns."""
    from addon.engine.passes import direct_light

    method = DirectMethod(gl, GIConfig(), RsmConfig(resolution=64))
    scene = make_scene(Light("POINT", [0, 0, 0.5], [0, 0, -1], [1, 1, 1], power_w=300.0))
    method.set_scene(scene)
    expected = method.run().images["direct"][::-1]  # back to texture row order
    junk = np.full((SIZE, SIZE, 4), 7.0, np.float32)
    direct = gl.texture((SIZE, SIZE), data=junk)
    views = method.light_views()
    assert len(views) == 6
    for i, view in enumerate(views):
        method._draw_rsm(view, 0, {})
        shadow, shadow_view = method.shadow_map(view)
        direct_light.run(gl, method.gbuf["position"], method.gbuf["normal"], shadow, direct, shadow_view,
                         method.rsm_config.shadow_bias_texels, method.emitters, accumulate=i > 0)
    got = gl.read(direct)
    seen = gl.read(method.gbuf["position"])[..., 3] != 0.0
    assert seen.any() and not seen.all()
    np.testing.assert_array_equal(got[seen][:, :3], expected[seen][:, :3])
    assert np.all(got[~seen] == 7.0)


def test_an_area_lights_penumbra_is_soft(gl):
    # A 1 m square light 2 m above the floor (2 x 2 patches) and a wall in the plane x = 0, 1 m high and
    # wider than the floor. A floor point at x < 0 sees the light's part with qx <= -x (the ray to
    # (qx, qy, 2) crosses x = 0 at height -2x / (qx - x) < 1 beyond it), so the exact light is the
    # polygon integral of that clipped square (area_light.polygon_irradiance): a penumbra from x = -0.5
    # to the wall. Shadowed from the patches' centres alone (qx = +-0.25) it is a step at x = -0.25: mean
    # |error| 0.077 of the unshadowed light along the transect. The soft shadows (PCSS per patch, their
    # penumbra capped at 16 texels) measured 0.042 with a 512-texel RSM; bound 0.05.
    wall = [[[0, -3, 0], [0, 3, 0], [0, 3, 1]], [[0, -3, 0], [0, 3, 1], [0, -3, 1]]]
    tris = np.array(quad(-1, 1, -1, 1, 0.0) + wall, np.float32)
    normals = np.zeros_like(tris)
    normals[:2, :, 2] = 1.0
    normals[2:, :, 0] = 1.0
    light = Light("AREA", [0, 0, H], [0, 0, -1], [1, 1, 1], power_w=300.0, area_shape="SQUARE", size_x_m=1.0,
                  size_y_m=1.0, axis_x=[1, 0, 0])
    cam = make_scene(light).camera
    scene = Scene(tris, normals, np.full((4, 3), 0.8, np.float32), np.zeros((4, 3), np.float32), [light], camera=cam)
    method = DirectMethod(gl, GIConfig(), RsmConfig(resolution=512, area_patches=2))
    method.set_scene(scene)
    img = method.run().images["direct"][..., 0]
    radiance = 300.0 / np.pi  # P / (pi A), A = 1 m^2
    up = np.array([0.0, 0.0, 1.0])

    def light_up_to(qx_max, p):
        corners = np.array([[-0.5, -0.5, H], [qx_max, -0.5, H], [qx_max, 0.5, H], [-0.5, 0.5, H]])
        return radiance * polygon_irradiance(p, up, corners) / np.pi

    row, _ = pixel_of(cam, np.zeros(3))
    errors, hard_errors = [], []
    for col in range(SIZE):
        p = floor_point_at_pixel(cam, row, col)
        if -0.75 < p[0] < -0.02:
            exact, unshadowed = light_up_to(min(0.5, -p[0]), p), light_up_to(0.5, p)
            hard = light_up_to(0.5 if -p[0] > 0.25 else 0.0, p)
            errors.append(abs(img[row, col] - exact) / unshadowed)
            hard_errors.append(abs(hard - exact) / unshadowed)
    assert len(errors) >= 15
    assert np.mean(hard_errors) == pytest.approx(0.077, abs=0.002)
    assert np.mean(errors) < 0.05


def test_the_floor_beside_a_wall_keeps_its_light(gl):
    # A floor meeting a wall (the plane x = 0.5, 1 m high, lit on its room side) under a point light at
    # (0, 0, 2): nothing blocks any floor point, so every floor pixel reads the point's exact irradiance
    # up to the wall. The normal offset makes the floor's last column before the wall look up the wall's
    # texels of the 64-texel map, nearer the light; the wall blocks only receivers behind its plane, so
    # they stay lit (without that test: 46 pixels read 0, measured).
    wall = [[[0.5, -1, 0], [0.5, 1, 0], [0.5, 1, 1]], [[0.5, -1, 0], [0.5, 1, 1], [0.5, -1, 1]]]
    tris = np.array(quad(-1, 0.5, -1, 1, 0.0) + wall, np.float32)
    normals = np.zeros_like(tris)
    normals[:2, :, 2] = 1.0
    normals[2:, :, 0] = -1.0
    light = Light("POINT", [0, 0, H], [0, 0, -1], [1, 1, 1], power_w=300.0)
    cam = make_scene(light).camera
    scene = Scene(tris, normals, np.full((4, 3), 0.8, np.float32), np.zeros((4, 3), np.float32), [light], camera=cam)
    method = DirectMethod(gl, GIConfig(), RsmConfig(resolution=64))
    method.set_scene(scene)
    img = method.run().images["direct"][..., 0]
    checked = 0
    for row in range(SIZE):
        for col in range(SIZE):
            p = floor_point_at_pixel(cam, row, col)
            if -0.98 < p[0] < 0.49 and abs(p[1]) < 0.95:
                assert img[row, col] == pytest.approx(point_irradiance_over_pi(300.0 / (4 * np.pi), p), rel=1e-4)
                checked += 1
    assert checked > 1000


def test_a_glowing_surface_does_not_light_itself(gl):
    # A 0.6 m emissive square of radiance L (albedo 0.5, as a Principled BSDF that also glows), tilted
    # 60 degrees over a floor, seen from above. Exact answers: the square's own pixels get nothing from
    # it (it lies in their tangent plane; Cycles' Diffuse Direct of an emitter holds no light of its
    # own), the floor E = L x the polygon's cosine-weighted solid angle (area_light.polygon_irradiance;
    # nothing blocks). A slanted plane puts the square's G-buffer positions a few fp32 ulps to either
    # side of it, where the square would fill their hemisphere: before the on-plane test 38 of its 91
    # pixels read L (measured). fp32: 1e-4 on the floor.
    radiance = 5.0
    t = np.radians(60.0)
    u, v = np.array([1.0, 0.0, 0.0]), np.array([0.0, np.cos(t), np.sin(t)])
    centre = np.array([0.1, 0.0, 0.35])
    corners = [centre + 0.3 * a * u + 0.3 * b * v for a, b in ((-1, -1), (1, -1), (1, 1), (-1, 1))]
    square = [[corners[0], corners[1], corners[2]], [corners[0], corners[2], corners[3]]]
    tris = np.array(quad(-1, 1, -1, 1, 0.0) + square, np.float32)
    normals = np.zeros_like(tris)
    normals[:2, :, 2] = 1.0
    normals[2:] = np.cross(u, v)
    albedo = np.array([[0.8] * 3, [0.8] * 3, [0.5] * 3, [0.5] * 3], np.float32)
    emission = np.zeros((4, 3), np.float32)
    emission[2:] = radiance
    cam = make_scene(None).camera
    scene = Scene(tris, normals, albedo, emission, [], camera=cam)
    method = DirectMethod(gl, GIConfig(), RsmConfig(resolution=256))
    method.set_scene(scene)
    images = method.run().images
    img, on_square = images["direct"][..., 0], images["albedo"][..., 0] == 0.5
    assert on_square.sum() > 80
    assert np.all(img[on_square] == 0.0)
    for world in ([-0.6, 0.5, 0.0], [0.7, -0.6, 0.0], [0.1, -0.6, 0.0]):
        row, col = pixel_of(cam, np.array(world))
        p = floor_point_at_pixel(cam, row, col)
        want = radiance * polygon_irradiance(p, np.array([0.0, 0.0, 1.0]), np.array(corners)) / np.pi
        assert img[row, col] == pytest.approx(want, rel=1e-4)


@pytest.mark.parametrize("winding", ["facing", "reversed"])
def test_the_triangles_side_decides_the_normals_flip_as_in_cycles(gl, winding):
    """Cycles decides a back face by the triangle's own normal and flips the shading normal with it, so
    a smooth normal that leans away from the viewer on a face that faces it stays as it is (a long wall
    triangle whose corners' normals lean into the walls beside it: the conference room's top strip read
    no light when the lean decided). A floor seen from above and lit by a sun from above, its corner
    normals all n = (-1, 0, 0.05) / |.|: n faces away from the camera and the sun at every pixel, while
    the triangle faces both. Exact: the G-buffer's and the RSM's normals are n, also where the triangle
    is wound downwards with corner normals -n (its back is seen: flipped to n)."""
    lean = np.array([-1.0, 0.0, 0.05]) / np.linalg.norm([-1.0, 0.0, 0.05])
    tris = np.array(quad(-1, 1, -1, 1, 0.0), np.float32)
    corner_normal = lean
    if winding == "reversed":  # wound downwards, its corner normals -lean on that side
        tris = tris[:, ::-1].copy()
        corner_normal = -lean
    normals = np.broadcast_to(corner_normal, tris.shape).astype(np.float32)
    expected = lean
    cam = Camera(look_along([0, 0, 5], [0, 0, -1], [0, 1, 0]), perspective(np.radians(30), 0.1, 100), SIZE, SIZE)
    scene = Scene(tris, normals, np.full((2, 3), 0.8, np.float32), np.zeros((2, 3), np.float32),
                  [Light("SUN", [0, 0, 0], [0, 0, -1], [1, 1, 1], sun_strength=2.0)], camera=cam)
    method = DirectMethod(gl, GIConfig(), RsmConfig(resolution=64))
    method.set_scene(scene)
    method.run()
    gbuffer = gl.read(method.gbuf["position"])[..., 3] > 0
    seen_normals = gl.read(method.gbuf["normal"])[..., :3][gbuffer]
    assert gbuffer.sum() > SIZE * SIZE // 4
    np.testing.assert_allclose(seen_normals, np.broadcast_to(expected, seen_normals.shape), atol=1e-5)
    rsm = gl.read(method.rsm["position"])[..., 3] > 0
    rsm_normals = gl.read(method.rsm["normal"])[..., :3][rsm]
    assert rsm.sum() > 0
    np.testing.assert_allclose(rsm_normals, np.broadcast_to(expected, rsm_normals.shape), atol=1e-5)


def _sample_texture(texture, u, v, nearest, clamp):
    """Cycles' Image Texture at (u, v): Closest or Linear (texel centres at (i + 0.5) / size), Repeat or
    Extend; texture (h, w, 3), row 0 = v 0."""
    h, w = texture.shape[:2]

    def texel(i, j):
        i, j = (np.clip(i, 0, h - 1), np.clip(j, 0, w - 1)) if clamp else (i % h, j % w)
        return texture[i, j]

    if nearest:
        return texel(int(np.floor(v * h)), int(np.floor(u * w)))
    x, y = u * w - 0.5, v * h - 0.5
    j0, i0 = int(np.floor(x)), int(np.floor(y))
    fx, fy = x - j0, y - i0
    bottom = (1 - fx) * texel(i0, j0) + fx * texel(i0, j0 + 1)
    top = (1 - fx) * texel(i0 + 1, j0) + fx * texel(i0 + 1, j0 + 1)
    return (1 - fy) * bottom + fy * top


@pytest.mark.parametrize("nearest", [True, False], ids=["closest", "linear"])
@pytest.mark.parametrize("clamp", [False, True], ids=["repeat", "extend"])
def test_the_camera_sees_a_base_color_texture_per_pixel(gl, nearest, clamp):
    """The G-buffer's albedo is the texel under each pixel's centre times the material's other factors
    (Scene.albedo_textures), sampled as Cycles samples an Image Texture, while the per-triangle albedo
    stays for the other passes. A floor seen at a slant (so the UVs need perspective-correct
    interpolation), its left half textured by a random 4 x 4 image whose UVs run from -0.5 to 1.5 (so
    Repeat and Extend differ), scale (0.5, 1, 3) (clipped at 1 as Cycles' Diffuse Color is); its right
    half flat 0.25. Exact up to fp32 interpolation of the UVs (atol 2e-4 against a bilinear slope of at
    most 4 per UV unit x the 4-texel image); Closest skips pixels within 1e-3 texel of a texel edge."""
    rng = np.random.default_rng(7)
    image = rng.uniform(0.05, 0.95, (4, 4, 3)).astype(np.float32)
    scale = np.array([0.5, 1.0, 3.0], np.float32)
    tris = np.array(quad(-1, 0, -1, 1, 0.0) + quad(0, 1, -1, 1, 0.0), np.float32)
    normals = np.zeros_like(tris)
    normals[..., 2] = 1.0

    def uv_of(p):  # x in [-1, 0] -> u in [-0.5, 1.5], y in [-1, 1] -> v in [-0.5, 1.5]
        return np.stack([(p[..., 0] + 1.0) * 2.0 - 0.5, (p[..., 1] + 1.0) - 0.5], axis=-1)

    textures = AlbedoTextures(images=[image], nearest=[nearest], clamp=[clamp], index=np.array([0, 0, -1, -1]),
                              uv=uv_of(tris).astype(np.float32), scale=np.tile(scale, (4, 1)),
                              bounce_scale=np.tile(scale, (4, 1)))
    cam = Camera(look_along([0.3, -2.5, 3.0], [-0.1, 0.6, -0.8], [0, 0, 1]), perspective(np.radians(40), 0.1, 100),
                 SIZE, SIZE)
    flat = np.full((4, 3), 0.25, np.float32)
    scene = Scene(tris, normals, flat, np.zeros((4, 3), np.float32),
                  [Light("SUN", [0, 0, 0], [0, 0, -1], [1, 1, 1], sun_strength=1.0)], camera=cam,
                  albedo_textures=textures)
    method = DirectMethod(gl, GIConfig(), RsmConfig(resolution=64))
    method.set_scene(scene)
    albedo = method.run().images["albedo"]
    checked = {"textured": 0, "flat": 0}
    for row in range(SIZE):
        for col in range(SIZE):
            if albedo[row, col, 3] <= 0:
                continue
            p = floor_point_at_pixel(cam, row, col)
            if abs(p[0]) < 0.02:  # the seam between the halves
                continue
            if p[0] > 0:
                np.testing.assert_allclose(albedo[row, col, :3], 0.25, atol=1e-6)
                checked["flat"] += 1
                continue
            u, v = uv_of(p)
            edge = np.abs(np.array([u, v]) * 4 - np.round(np.array([u, v]) * 4))
            if nearest and edge.min() < 1e-3:
                continue
            expected = np.clip(_sample_texture(image, u, v, nearest, clamp) * scale, 0.0, 1.0)
            np.testing.assert_allclose(albedo[row, col, :3], expected, atol=2e-4)
            checked["textured"] += 1
    assert checked["textured"] > 300 and checked["flat"] > 300


def test_the_albedo_atlas_is_packed_again_only_for_other_images(gl):
    # A geometry change (set_scene) keeps the uploaded atlas while the texture images are the same
    # arrays (the capture keeps an unchanged image's texels), and packs again for a new array.
    image = np.ones((2, 2, 3), np.float32)
    tris = np.array(quad(-1, 1, -1, 1, 0.0), np.float32)
    normals = np.zeros_like(tris)
    normals[..., 2] = 1.0

    def scene(img):
        textures = AlbedoTextures(images=[img], nearest=[True], clamp=[False], index=np.zeros(2, np.int32),
                                  uv=np.zeros((2, 3, 2), np.float32), scale=np.ones((2, 3), np.float32),
                                  bounce_scale=np.ones((2, 3), np.float32))
        return Scene(tris, normals, np.full((2, 3), 0.5, np.float32), np.zeros((2, 3), np.float32), [],
                     albedo_textures=textures)

    method = DirectMethod(gl, GIConfig(), RsmConfig(resolution=64))
    method.set_scene(scene(image))
    first = method.albedo_atlas
    method.set_scene(scene(image))
    assert method.albedo_atlas is first
    method.set_scene(scene(image.copy()))
    assert method.albedo_atlas is not first
