"""Capture (depsgraph -> Scene): geometry, instances, visibility, lights, materials, units, camera,
incremental updates, and the albedo against Cycles' Diffuse Color pass. Every scene is built here."""

from __future__ import annotations

import math

import numpy as np
import pytest

bpy = pytest.importorskip("bpy")

from addon.bridge import capture as cap  # noqa: E402

pytestmark = pytest.mark.blender

CUBE_V = [(x, y, z) for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)]
CUBE_F = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]


def _obj(name, verts, faces, location=(0, 0, 0), link=True):
    me = bpy.data.meshes.new(name)
    me.from_pydata(verts, [], faces)
    ob = bpy.data.objects.new(name, me)
    ob.location = location
    if link:
        bpy.context.scene.collection.objects.link(ob)
    return ob


def _plane_cube():
    plane = _obj("Plane", [(-1, -1, 0), (1, -1, 0), (1, 1, 0), (-1, 1, 0)], [(0, 1, 2, 3)])
    cube = _obj("Cube", CUBE_V, CUBE_F, location=(0, 0, 3))
    return plane, cube


def _dg():
    bpy.context.view_layer.update()
    return bpy.context.evaluated_depsgraph_get()


def _principled(name, **inputs):
    mat = bpy.data.materials.new(name)
    bsdf = mat.node_tree.nodes["Principled BSDF"]
    for k, v in inputs.items():
        bsdf.inputs[k].default_value = v
    return mat


def _plane_head_on(tmp_path, inputs: dict, spp: int, pass_name: str, base_image=None, material=None):
    """A 100 m Principled plane (`inputs`; `base_image`, if given, an Image Texture into its Base Color;
    or `material`) filling a 16 x 16 Cycles render from 10 m above: returns the capture and the render's
    layers, with `pass_name` ("Diffuse Color" or "Glossy Color") enabled."""
    from addon.bridge import compat
    from addon.bridge.images import read_multilayer

    plane = _obj("Plane", [(-50, -50, 0), (50, -50, 0), (50, 50, 0), (-50, 50, 0)], [(0, 1, 2, 3)])
    mat = material if material is not None else _principled("M", **inputs)
    if base_image is not None:
        tex = mat.node_tree.nodes.new("ShaderNodeTexImage")
        tex.image = base_image
        mat.node_tree.links.new(tex.outputs["Color"], mat.node_tree.nodes["Principled BSDF"].inputs["Base Color"])
    plane.data.materials.append(mat)
    cam = bpy.data.objects.new("Cam", bpy.data.cameras.new("Cam"))
    cam.data.lens = 200
    cam.location = (0, 0, 10)
    sc = bpy.context.scene
    sc.collection.objects.link(cam)
    sc.camera = cam
    r = sc.render
    r.engine, r.resolution_x, r.resolution_y, r.resolution_percentage = "CYCLES", 16, 16, 100
    sc.cycles.samples, sc.cycles.use_denoising, sc.cycles.use_adaptive_sampling = spp, False, False
    sc.cycles.filter_width = 0.01
    setattr(bpy.context.view_layer, {"Diffuse Color": "use_pass_diffuse_color",
                                     "Glossy Color": "use_pass_glossy_color"}[pass_name], True)
    compat.multilayer_exr(r.image_settings)
    r.image_settings.exr_codec = "NONE"  # what read_multilayer reads
    r.filepath, r.use_file_extension = str(tmp_path / "r.exr"), False
    s = cap.capture(_dg())
    bpy.ops.render.render(write_still=True)
    return s, read_multilayer(tmp_path / "r.exr")


def test_plane_and_cube_triangles_positions_normals(fresh_blend):
    _plane_cube()
    s = cap.capture(_dg())
    assert s.triangle_count == 2 + 12  # exact
    lo, hi = s.bounds_m()
    np.testing.assert_allclose(lo, [-1, -1, 0], atol=1e-6)
    np.testing.assert_allclose(hi, [1, 1, 4], atol=1e-6)  # cube at z=3, half size 1
    np.testing.assert_allclose(np.linalg.norm(s.normals, axis=-1), 1.0, atol=1e-6)
    # Default (no material): Cycles' 0.8 grey, no warning for it.
    np.testing.assert_allclose(s.albedo, 0.8, atol=1e-7)
    assert s.warnings == []
    assert s.camera is None  # no camera in the file


def test_modifier_and_transform(fresh_blend):
    _, cube = _plane_cube()
    mod = cube.modifiers.new("arr", "ARRAY")
    mod.count = 2  # relative offset 1 along X: a second cube at x + 2
    cube.rotation_euler = (0, 0, math.pi / 2)  # local X -> world Y
    cube.scale = (1, 1, 0.5)
    s = cap.capture(_dg())
    assert s.triangle_count == 2 + 24
    cube_pts = s.positions_m[2:].reshape(-1, 3)
    np.testing.assert_allclose(cube_pts.min(0), [-1, -1, 2.5], atol=1e-6)
    np.testing.assert_allclose(cube_pts.max(0), [1, 3, 3.5], atol=1e-6)
    # Normals follow the inverse transpose: the top faces still point +Z, unit length.
    top = np.all(np.abs(cube_pts.reshape(-1, 3, 3)[:, :, 2] - 3.5) < 1e-6, axis=1)
    np.testing.assert_allclose(s.normals[2:][top], np.broadcast_to([0, 0, 1], s.normals[2:][top].shape), atol=1e-6)


def test_collection_instance(fresh_blend):
    coll = bpy.data.collections.new("Parts")
    cube = _obj("PartCube", CUBE_V, CUBE_F, link=False)
    coll.objects.link(cube)
    empty = bpy.data.objects.new("Inst", None)
    empty.instance_type = "COLLECTION"
    empty.instance_collection = coll
    empty.location = (5, 0, 0)
    empty.rotation_euler = (0, 0, math.pi / 4)
    bpy.context.scene.collection.objects.link(empty)
    s = cap.capture(_dg())
    assert s.triangle_count == 12
    r = math.sqrt(2)  # the cube rotated 45 degrees about Z reaches sqrt(2) along X and Y
    np.testing.assert_allclose(s.bounds_m()[0], [5 - r, -r, -1], atol=1e-6)
    np.testing.assert_allclose(s.bounds_m()[1], [5 + r, r, 1], atol=1e-6)


def _gn_scatter():
    """A host whose geometry nodes put 3 instances of a 2 m cube at x = 0, 4, 8 (host at y = 10)."""
    src = _obj("Src", CUBE_V, CUBE_F, link=False)  # not in the scene: only its instances render
    ng = bpy.data.node_groups.new("Scatter", "GeometryNodeTree")
    ng.interface.new_socket("Geometry", in_out="OUTPUT", socket_type="NodeSocketGeometry")
    line = ng.nodes.new("GeometryNodeMeshLine")
    line.inputs["Count"].default_value = 3
    line.inputs["Offset"].default_value = (4, 0, 0)
    info = ng.nodes.new("GeometryNodeObjectInfo")
    info.inputs["Object"].default_value = src
    iop = ng.nodes.new("GeometryNodeInstanceOnPoints")
    out = ng.nodes.new("NodeGroupOutput")
    ng.links.new(line.outputs["Mesh"], iop.inputs["Points"])
    ng.links.new(info.outputs["Geometry"], iop.inputs["Instance"])
    ng.links.new(iop.outputs["Instances"], out.inputs[0])
    host = _obj("Host", [(0, 0, 0), (1, 0, 0), (0, 1, 0)], [(0, 1, 2)], location=(0, 10, 0))
    host.modifiers.new("gn", "NODES").node_group = ng
    return host


def test_geometry_nodes_instances(fresh_blend):
    _gn_scatter()
    s = cap.capture(_dg())
    assert s.triangle_count == 3 * 12  # the host's own triangle is replaced by the instances
    np.testing.assert_allclose(s.bounds_m()[0], [-1, 9, -1], atol=1e-6)
    np.testing.assert_allclose(s.bounds_m()[1], [9, 11, 1], atol=1e-6)


def test_hidden_holdout_and_camera_invisible(fresh_blend):
    plane, cube = _plane_cube()
    cube.hide_render = True
    assert cap.capture(_dg()).triangle_count == 2
    cube.hide_render = False
    cube.is_holdout = True
    assert cap.capture(_dg()).triangle_count == 2
    cube.is_holdout = False
    cube.visible_camera = False  # still bounces light in Cycles: kept
    assert cap.capture(_dg()).triangle_count == 14
    coll = bpy.data.collections.new("Hidden")
    bpy.context.scene.collection.children.link(coll)
    coll.objects.link(_obj("Other", CUBE_V, CUBE_F, link=False))
    coll.hide_render = True
    assert cap.capture(_dg()).triangle_count == 14


def _lamp(kind, location=(1, 2, 3), rotation=(0, 0, 0), **props):
    ld = bpy.data.lights.new(kind.lower(), kind)
    for k, v in props.items():
        setattr(ld, k, v)
    ob = bpy.data.objects.new(kind.lower(), ld)
    ob.location, ob.rotation_euler = location, rotation
    bpy.context.scene.collection.objects.link(ob)
    return ob


def test_lights(fresh_blend):
    _lamp("POINT", energy=100.0, color=(1, 0.5, 0.25))
    _lamp("SPOT", rotation=(math.pi / 2, 0, 0), energy=50.0, spot_size=0.8, spot_blend=0.3,
          shadow_soft_size=0.2)
    _lamp("SUN", energy=3.0, angle=0.1)
    _lamp("AREA", rotation=(0, 0, math.pi / 2), energy=20.0, shape="RECTANGLE", size=2.0, size_y=0.5)
    s = cap.capture(_dg())
    by = {li.kind: li for li in s.lights}
    assert sorted(by) == ["AREA", "POINT", "SPOT", "SUN"]
    p, sp, sun, ar = by["POINT"], by["SPOT"], by["SUN"], by["AREA"]
    np.testing.assert_allclose(p.position_m, [1, 2, 3], atol=1e-6)
    np.testing.assert_allclose(p.color, [1, 0.5, 0.25], atol=1e-6)
    assert p.power_w == pytest.approx(100.0)
    np.testing.assert_allclose(p.direction, [0, 0, -1], atol=1e-6)
    # Rotating 90 degrees about X turns -Z into +Y.
    np.testing.assert_allclose(sp.direction, [0, 1, 0], atol=1e-6)
    assert (sp.power_w, sp.spot_size_rad, sp.spot_blend) == pytest.approx((50.0, 0.8, 0.3), abs=1e-6)
    assert (sun.sun_strength, sun.sun_angle_rad) == pytest.approx((3.0, 0.1), abs=1e-6)
    assert ar.area_shape == "RECTANGLE" and ar.power_w == pytest.approx(20.0)
    assert (ar.size_x_m, ar.size_y_m) == pytest.approx((2.0, 0.5), abs=1e-6)
    np.testing.assert_allclose(ar.axis_x, [0, 1, 0], atol=1e-6)  # local X rotated about Z
    assert [w for w in s.warnings if "radius" in w and "spot" in w]  # the spot's soft radius is reported
    assert len(s.warnings) == 1


def test_light_exposure_scales_power(fresh_blend):
    # Blender 4.4+ multiplies a lamp's energy by 2^exposure (Light > Exposure); Cycles emits that.
    _lamp("POINT", energy=100.0, exposure=1.5)
    _lamp("SUN", energy=3.0, exposure=-1.0)
    by = {li.kind: li for li in cap.capture(_dg()).lights}
    assert by["POINT"].power_w == pytest.approx(100.0 * 2**1.5, rel=1e-6)
    assert by["SUN"].sun_strength == pytest.approx(1.5, rel=1e-6)


def test_emission_principled_and_emission_shader(fresh_blend):
    plane, cube = _plane_cube()
    plane.data.materials.append(_principled("Glow", **{"Emission Color": (1, 0.5, 0.25, 1),
                                                       "Emission Strength": 3.0}))
    mat = bpy.data.materials.new("Pure")
    nt = mat.node_tree
    nt.nodes.remove(nt.nodes["Principled BSDF"])
    em = nt.nodes.new("ShaderNodeEmission")
    em.inputs["Color"].default_value = (0.2, 0.4, 1.0, 1)
    em.inputs["Strength"].default_value = 2.0
    nt.links.new(em.outputs[0], nt.nodes["Material Output"].inputs["Surface"])
    cube.data.materials.append(mat)
    s = cap.capture(_dg())
    np.testing.assert_allclose(s.emission[:2], [[3, 1.5, 0.75]] * 2, rtol=1e-6)
    np.testing.assert_allclose(s.emission[2:], [[0.4, 0.8, 2.0]] * 12, rtol=1e-6)
    np.testing.assert_allclose(s.albedo[2:], 0.0)  # a pure emitter reflects nothing
    assert s.warnings == []


def test_unit_scale(fresh_blend):
    _, cube = _plane_cube()
    _lamp("AREA", location=(0, 0, 10), energy=20.0, size=2.0)
    bpy.context.scene.unit_settings.scale_length = 0.01
    s = cap.capture(_dg())
    np.testing.assert_allclose(s.bounds_m()[1], [0.01, 0.01, 0.04], atol=1e-8)
    np.testing.assert_allclose(s.lights[0].position_m, [0, 0, 0.1], atol=1e-8)
    assert s.lights[0].size_x_m == pytest.approx(0.02) and s.lights[0].power_w == pytest.approx(20.0)


def test_degenerate_triangles_dropped_with_one_warning(fresh_blend):
    nan = float("nan")
    verts = [(0, 0, 0), (1, 0, 0), (0, 1, 0),            # good
             (0, 0, 1), (1, 0, 1), (2, 0, 1),            # collinear: zero area
             (0, 0, 2), (1, 0, 2), (nan, 1, 2)]          # NaN corner
    _obj("Bad", verts, [(0, 1, 2), (3, 4, 5), (6, 7, 8)])
    s = cap.capture(_dg())
    assert s.triangle_count == 1
    assert [w for w in s.warnings if w.startswith("2 triangles")] and len(s.warnings) == 1


def test_unsupported_material_neutral_albedo_and_one_warning(fresh_blend):
    plane, cube = _plane_cube()
    mat = bpy.data.materials.new("Waxy")
    nt = mat.node_tree
    mix = nt.nodes.new("ShaderNodeMixShader")  # one unsupported closure makes the whole surface so
    nt.links.new(nt.nodes.new("ShaderNodeBsdfTranslucent").outputs[0], mix.inputs[1])
    nt.links.new(nt.nodes.new("ShaderNodeBsdfDiffuse").outputs[0], mix.inputs[2])
    nt.links.new(mix.outputs[0], nt.nodes["Material Output"].inputs["Surface"])
    plane.data.materials.append(mat)
    cube.data.materials.append(mat)  # two users: still one warning
    s = cap.capture(_dg())
    np.testing.assert_allclose(s.albedo, cap.NEUTRAL_ALBEDO)
    np.testing.assert_allclose(s.bounce_albedo, cap.NEUTRAL_ALBEDO)
    warnings = [w for w in s.warnings if "'Waxy'" in w]
    assert len(warnings) == 1 and len(s.warnings) == 1 and "ShaderNodeBsdfTranslucent" in warnings[0]


def _mixed(name: str, mix_factor: float | None):
    """A Diffuse BSDF (0.6, 0.3, 0.1) with a Glossy BSDF (0.2, 0.4, 0.6, roughness 0.3) added
    (mix_factor None) or, through a Mix Shader of that factor, a Principled BSDF (0.2, 0.5, 0.8,
    Specular IOR Level 1, roughness 0.5) through a reroute."""
    mat = bpy.data.materials.new(name)
    nt = mat.node_tree
    nt.nodes.remove(nt.nodes["Principled BSDF"])
    diffuse = nt.nodes.new("ShaderNodeBsdfDiffuse")
    diffuse.inputs["Color"].default_value = (0.6, 0.3, 0.1, 1)
    if mix_factor is None:
        other = nt.nodes.new("ShaderNodeBsdfGlossy")
        other.inputs["Color"].default_value = (0.2, 0.4, 0.6, 1)
        other.inputs["Roughness"].default_value = 0.3
        join = nt.nodes.new("ShaderNodeAddShader")
        nt.links.new(diffuse.outputs[0], join.inputs[0])
        nt.links.new(other.outputs[0], join.inputs[1])
    else:
        other = nt.nodes.new("ShaderNodeBsdfPrincipled")
        other.inputs["Base Color"].default_value = (0.2, 0.5, 0.8, 1)
        other.inputs["Specular IOR Level"].default_value = 1.0
        other.inputs["Roughness"].default_value = 0.5
        reroute = nt.nodes.new("NodeReroute")
        nt.links.new(other.outputs[0], reroute.inputs[0])
        join = nt.nodes.new("ShaderNodeMixShader")
        join.inputs[0].default_value = mix_factor
        nt.links.new(diffuse.outputs[0], join.inputs[1])
        nt.links.new(reroute.outputs[0], join.inputs[2])
    nt.links.new(join.outputs[0], nt.nodes["Material Output"].inputs["Surface"])
    return mat


@pytest.mark.parametrize("mix_factor", [None, 0.25])
def test_added_and_mixed_closures_match_cycles_diffuse_color(fresh_blend, tmp_path, mix_factor):
    """Add Shader and Mix Shader sum their closures' weights: the captured albedo equals Cycles' Diffuse
    Color pass (tolerance as in test_albedo_matches_cycles_diffuse_color). Exact values: Add (Diffuse,
    Glossy): the diffuse colour (a Glossy BSDF has no diffuse part), F0 the glossy colour; Mix 0.25:
    0.75 x diffuse + 0.25 x the Principled's base x 0.9254 (its layer, measured head-on), and toward
    other surfaces 0.75 x diffuse + 0.25 x base (no layer after a diffuse bounce)."""
    s, layers = _plane_head_on(tmp_path, {}, spp=1, pass_name="Diffuse Color",
                               material=_mixed("Mixed", mix_factor))
    diff_col = layers["Diffuse Color"][:, :, :3]
    np.testing.assert_allclose(diff_col, np.broadcast_to(s.albedo[0], diff_col.shape), atol=2e-3)
    diffuse, base = np.array([0.6, 0.3, 0.1]), np.array([0.2, 0.5, 0.8])
    if mix_factor is None:
        np.testing.assert_allclose(s.albedo[0], diffuse, atol=1e-6)
        np.testing.assert_allclose(s.bounce_albedo[0], diffuse, atol=1e-6)
        np.testing.assert_allclose(s.specular[0], [0.2, 0.4, 0.6], atol=1e-6)
        assert s.roughness[0] == pytest.approx(0.3)
    else:
        np.testing.assert_allclose(s.albedo[0], 0.75 * diffuse + 0.25 * base * 0.9254, atol=1e-3)
        np.testing.assert_allclose(s.bounce_albedo[0], 0.75 * diffuse + 0.25 * base, atol=1e-6)
        np.testing.assert_allclose(s.specular[0], 0.25 * 0.08, atol=1e-6)  # F0 0.04 x 2 x level 1
    assert s.warnings == []


def test_image_texture_average_and_world(fresh_blend):
    plane, _ = _plane_cube()
    img = bpy.data.images.new("tex", 2, 1, float_buffer=True)
    img.pixels[:] = [0.2, 0.4, 0.6, 1, 0.6, 0.0, 0.2, 1]
    mat = _principled("Tex", **{"Specular IOR Level": 0.0})
    nt = mat.node_tree
    tex = nt.nodes.new("ShaderNodeTexImage")
    tex.image = img
    nt.links.new(tex.outputs["Color"], nt.nodes["Principled BSDF"].inputs["Base Color"])
    plane.data.materials.append(mat)
    world = bpy.data.worlds.new("W")
    bg = world.node_tree.nodes["Background"]
    bg.inputs["Color"].default_value = (0.5, 0.25, 1.0, 1)
    bg.inputs["Strength"].default_value = 2.0
    bpy.context.scene.world = world
    s = cap.capture(_dg())
    np.testing.assert_allclose(s.albedo[:2], [[0.4, 0.2, 0.4]] * 2, atol=1e-6)  # level 0: no layer
    np.testing.assert_allclose(s.world_color, [1.0, 0.5, 2.0], atol=1e-6)
    assert s.warnings == []


@pytest.mark.parametrize("level,metallic", [(0.0, 0.0), (0.5, 0.0), (1.0, 0.25)])
def test_albedo_matches_cycles_diffuse_color(fresh_blend, tmp_path, level, metallic):
    """Head-on view of a plane: captured albedo vs Cycles' Diffuse Color pass, every pixel, 1 spp.

    Tolerance 0.002 absolute: the pass is noise-free for a plane, and over this narrow view (< 3 degrees
    off the normal) the dielectric factor varies < 0.001; our table fits the measurement to < 0.001.
    """
    base = (0.6, 0.3, 0.1, 1)
    s, layers = _plane_head_on(tmp_path, {"Base Color": base, "Specular IOR Level": level, "Metallic": metallic},
                               spp=1, pass_name="Diffuse Color")
    diff_col = layers["Diffuse Color"][:, :, :3]
    assert diff_col.shape == (16, 16, 3)
    np.testing.assert_allclose(diff_col, np.broadcast_to(s.albedo[0], diff_col.shape), atol=2e-3)
    expected_factor = {0.0: 1.0, 0.5: 0.9626, 1.0: 0.9254}[level]  # measured head-on (module docstring)
    np.testing.assert_allclose(s.albedo[0], np.array(base[:3]) * (1 - metallic) * expected_factor, atol=1e-3)
    # Toward other surfaces the layer is gone, as in Cycles after a diffuse bounce (tests/e2e/
    # test_glossy_bounce.py); exact: the same product without the factor.
    np.testing.assert_allclose(s.bounce_albedo[0], np.array(base[:3]) * (1 - metallic), atol=1e-6)


def test_an_image_blender_cannot_load_reads_as_cycles_renders_it(fresh_blend, tmp_path):
    """A Base Color image whose file is gone: Cycles renders it magenta (1, 0, 1), and the capture must
    light that scene, not the socket's default colour; one warning names the image. Tolerance as in
    test_albedo_matches_cycles_diffuse_color (Specular IOR Level 0: no dielectric factor)."""
    img = bpy.data.images.new("gone", 4, 4)
    img.source, img.filepath = "FILE", str(tmp_path / "no-such-texture.png")
    img.reload()
    s, layers = _plane_head_on(tmp_path, {"Specular IOR Level": 0.0, "Base Color": (0.2, 0.8, 0.2, 1)},
                               spp=1, pass_name="Diffuse Color", base_image=img)
    diff_col = layers["Diffuse Color"][:, :, :3]
    np.testing.assert_allclose(diff_col, np.broadcast_to([1.0, 0.0, 1.0], diff_col.shape), atol=2e-3)
    np.testing.assert_allclose(s.albedo[0], diff_col[8, 8], atol=2e-3)
    assert len(s.warnings) == 1 and "'gone'" in s.warnings[0] and "magenta" in s.warnings[0]


def test_camera_projection_matches_world_to_camera_view(fresh_blend):
    from bpy_extras.object_utils import world_to_camera_view
    from mathutils import Vector

    sc = bpy.context.scene
    cam = bpy.data.objects.new("Cam", bpy.data.cameras.new("Cam"))
    cam.location, cam.rotation_euler = (3, -4, 2), (1.2, 0.0, 0.6)
    sc.collection.objects.link(cam)
    sc.camera = cam
    sc.render.resolution_x, sc.render.resolution_y, sc.render.resolution_percentage = 320, 180, 50
    sc.unit_settings.scale_length = 0.5  # the camera must agree with positions in metres
    s = cap.capture(_dg())
    assert (s.camera.width, s.camera.height) == (160, 90)
    for p_bu in [(0.3, 0.2, 0.5), (-0.5, 1.0, 0.0), (1.0, -1.0, 1.0)]:
        ref = world_to_camera_view(sc, cam, Vector(p_bu))  # x, y in [0, 1] from bottom-left; z = depth
        clip = s.camera.view_projection @ np.array([*(np.array(p_bu) * 0.5), 1.0])
        ndc = clip[:3] / clip[3]
        np.testing.assert_allclose((ndc[:2] + 1) / 2, [ref.x, ref.y], atol=1e-6)
        view_pt = s.camera.view @ np.array([*(np.array(p_bu) * 0.5), 1.0])
        assert -view_pt[2] == pytest.approx(ref.z * 0.5, abs=1e-6)  # depth in metres
    np.testing.assert_allclose(s.camera.position_m, np.array([3, -4, 2]) * 0.5, atol=1e-6)
    assert cap.image_size(sc, 256) == (256, 144)
    sc.render.resolution_x = 100
    assert cap.image_size(sc, 256) == (142, 256)


def test_incremental_updates_count_geometry_reads(fresh_blend):
    plane, cube = _plane_cube()
    lamp = _lamp("POINT", energy=10.0)
    cache = cap.SceneCache()
    results = []

    def handler(scene, depsgraph):
        results.append(cache.update(depsgraph))

    first = cache.update(_dg())
    assert cache.geometry_reads == 2
    bpy.app.handlers.depsgraph_update_post.append(handler)
    try:
        lamp.location = (4, 4, 4)
        _dg()
        assert cache.geometry_reads == 2  # a moved light re-reads no mesh
        np.testing.assert_allclose(results[-1].lights[0].position_m, [4, 4, 4], atol=1e-6)
        cube.location = (0, 0, 5)
        _dg()
        assert cache.geometry_reads == 2  # a moved object re-applies its matrix only
        np.testing.assert_allclose(results[-1].bounds_m()[1], [1, 1, 6], atol=1e-6)
        cube.modifiers.new("arr", "ARRAY").count = 2
        _dg()
        assert cache.geometry_reads == 3  # one edited mesh: one re-read
        assert results[-1].triangle_count == 2 + 24
    finally:
        bpy.app.handlers.depsgraph_update_post.remove(handler)
    assert first.triangle_count == 14
    # Outside the handler depsgraph.updates is empty: the evaluated-mesh fingerprint still sees a
    # modifier change (one re-read), and nothing else is re-read.
    cube.modifiers["arr"].count = 3
    s = cache.update(_dg())
    assert cache.geometry_reads == 4 and s.triangle_count == 2 + 36
    cache.update(_dg())
    assert cache.geometry_reads == 4


def test_unchanged_instances_are_not_reread(fresh_blend):
    host = _gn_scatter()
    lamp = _lamp("SUN")
    cache = cap.SceneCache()
    cache.update(_dg())
    assert cache.geometry_reads == 4  # the host's own (empty) mesh + one per instance
    lamp.location.z = 7
    host.location.x = 1
    s = cache.update(_dg())
    assert cache.geometry_reads == 4 and s.triangle_count == 36
    np.testing.assert_allclose(s.bounds_m()[0], [0, 9, -1], atol=1e-6)


def test_image_texture_averaged_per_triangle(fresh_blend):
    # A quad cut into 16 x 16 x 2 triangles, UV = (x, y) / 2 + 0.5, textured with a 256-px ramp whose
    # texel i holds (i + 0.5) / 256 in red: each triangle's albedo is the ramp's mean over the triangle,
    # i.e. its UV centroid's u (exact for a linear function; nearest-texel lookup adds <= 1/512 per sample).
    import bmesh

    me = bpy.data.meshes.new("Grid")
    bm = bmesh.new()
    bm.loops.layers.uv.new("UVMap")  # calc_uvs fills an existing layer
    bmesh.ops.create_grid(bm, x_segments=16, y_segments=16, size=1.0, calc_uvs=True)
    bm.to_mesh(me)
    bm.free()
    ob = bpy.data.objects.new("Grid", me)
    bpy.context.scene.collection.objects.link(ob)
    img = bpy.data.images.new("ramp", 256, 1, float_buffer=True)
    ramp = (np.arange(256) + 0.5) / 256
    rgba = np.stack([ramp, np.zeros(256), np.zeros(256), np.ones(256)], axis=1)
    img.pixels.foreach_set(rgba.ravel().astype(np.float32))
    mat = _principled("Ramp", **{"Specular IOR Level": 0.0})
    tex = mat.node_tree.nodes.new("ShaderNodeTexImage")
    tex.image = img
    mat.node_tree.links.new(tex.outputs["Color"], mat.node_tree.nodes["Principled BSDF"].inputs["Base Color"])
    ob.data.materials.append(mat)
    s = cap.capture(_dg())
    assert s.triangle_count == 512
    # bmesh's grid UVs run 0..1 across the grid's x: u = x / 2 + 0.5 for x in [-1, 1].
    u_centroid = s.positions_m[:, :, 0].mean(axis=1) / 2 + 0.5
    np.testing.assert_allclose(s.albedo[:, 0], u_centroid, atol=1 / 256)
    assert np.ptp(s.albedo[:, 0]) > 0.9  # per triangle, not one average (which would be 0.5)
    np.testing.assert_allclose(s.albedo[:, 1:], 0.0)
    # The camera samples the same texture per pixel (Scene.albedo_textures): the image itself, every
    # triangle's corner UVs, Linear and Repeat (the node's defaults), and the factor 1 / 1 (Base Color is
    # the texture alone; the factor's red is albedo / the texture's mean, 0.5 / 0.5).
    t = s.albedo_textures
    (image,) = t.images
    np.testing.assert_allclose(image[0, :, 0], ramp, rtol=1e-6)
    assert t.nearest == [False] and t.clamp == [False]
    np.testing.assert_array_equal(t.index, 0)
    np.testing.assert_allclose(t.uv[..., 0], s.positions_m[..., 0] / 2 + 0.5, atol=1e-6)
    np.testing.assert_allclose(t.scale, np.broadcast_to([1.0, 0.0, 0.0], t.scale.shape), atol=1e-6)
    np.testing.assert_allclose(t.bounce_scale, t.scale, atol=1e-6)  # no glossy layer: the same factor


@pytest.mark.parametrize("metallic,level,roughness", [(0.25, 1.0, 0.3), (1.0, 0.5, 0.5), (0.0, 0.5, 0.2),
                                                      (0.0, 1.0, 0.8)])
def test_glossy_lobe_matches_cycles_glossy_color(fresh_blend, tmp_path, metallic, level, roughness):
    """Captured F0 = metallic x base + (1 - metallic) x 0.04 x 2 x level (IOR 1.5), roughness as set;
    the lobe's albedo our glossy pass multiplies by, (F0 A + B) x the multiple-scattering factor at
    n.v = 1 (addon/engine/brdf.py), against Cycles' Glossy Color pass of a plane seen head-on (16 spp,
    noise < 1e-4). Measured ratios 0.998-1.001 for metals and smooth dielectrics, 0.976 at roughness 0.8
    for a dielectric (Cycles uses the exact dielectric Fresnel, we Schlick's): bound 3 %."""
    from addon.engine import brdf

    base = np.array([0.6, 0.3, 0.1])
    s, layers = _plane_head_on(tmp_path, {"Base Color": (*base, 1), "Specular IOR Level": level,
                                          "Metallic": metallic, "Roughness": roughness},
                               spp=16, pass_name="Glossy Color")
    f0 = metallic * base + (1 - metallic) * 0.04 * 2 * level
    np.testing.assert_allclose(s.specular[0], f0, atol=1e-6)
    assert s.roughness[0] == pytest.approx(roughness, abs=1e-6)
    cycles = layers["Glossy Color"][:, :, :3].mean(axis=(0, 1))
    a, b = brdf.split_albedo(1.0, roughness)
    ours = (f0 * a + b) * brdf.multiscatter_factor(a, b, f0)
    print("ours / Cycles' Glossy Color:", ours / cycles)
    np.testing.assert_allclose(ours, cycles, rtol=0.03)


def test_diffuse_and_unsupported_surfaces_have_no_glossy_lobe(fresh_blend):
    """A Diffuse BSDF (and no material at all) captures F0 = 0, roughness 1: the glossy pass skips it."""
    plane = _obj("Plane", [(-1, -1, 0), (1, -1, 0), (1, 1, 0), (-1, 1, 0)], [(0, 1, 2, 3)])
    mat = bpy.data.materials.new("D")
    tree = mat.node_tree
    tree.nodes.remove(tree.nodes["Principled BSDF"])
    diffuse = tree.nodes.new("ShaderNodeBsdfDiffuse")
    tree.links.new(diffuse.outputs[0], tree.nodes["Material Output"].inputs["Surface"])
    plane.data.materials.append(mat)
    _obj("Bare", [(-1, -1, 1), (1, -1, 1), (1, 1, 1), (-1, 1, 1)], [(0, 1, 2, 3)])
    s = cap.capture(_dg())
    assert s.triangle_count == 4
    np.testing.assert_array_equal(s.specular, np.zeros((4, 3)))
    np.testing.assert_array_equal(s.roughness, np.ones(4))
