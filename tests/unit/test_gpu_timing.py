"""tools/gpu_timing.py without a GPU: scene files round-trip, camera resizing, timing summaries."""

import importlib.util
from pathlib import Path

import numpy as np

from addon.engine.scene import Camera, Light, Scene

ROOT = Path(__file__).resolve().parents[2]
_spec = importlib.util.spec_from_file_location("gpu_timing", ROOT / "tools" / "gpu_timing.py")
gpu_timing = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(gpu_timing)


def _scene() -> Scene:
    pos = np.array([[[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 0, 1], [1, 0, 1], [0, 1, 1]]], np.float32)
    proj = np.diag([1.0, 16 / 9, -1.0, 0.0])
    proj[3, 2] = -1.0
    return Scene(positions_m=pos, normals=np.tile([0, 0, 1], (2, 3, 1)).astype(np.float32),
                 albedo=np.full((2, 3), 0.5, np.float32), emission=np.zeros((2, 3), np.float32),
                 lights=[Light("SPOT", [0, 0, 2], [0, 0, -1], [1, 1, 1], power_w=300.0, spot_size_rad=1.2,
                               spot_blend=0.15, name="Spot")],
                 world_color=np.array([0.1, 0.2, 0.3], np.float32),
                 camera=Camera(np.eye(4), proj, 1920, 1080), camera_visible=np.array([True, False]),
                 specular=np.array([[0.04] * 3, [0.9, 0.6, 0.2]], np.float32),
                 roughness=np.array([0.5, 0.1], np.float32))


def test_scene_round_trip(tmp_path):
    scene = _scene()
    gpu_timing.save_scene(scene, tmp_path / "s", {"name": "s"})
    back = gpu_timing.load_scene(tmp_path / "s")
    for name in ("positions_m", "normals", "albedo", "emission", "camera_visible", "world_color", "specular",
                 "roughness"):
        np.testing.assert_array_equal(getattr(back, name), getattr(scene, name))
    assert back.positions_m.dtype == np.float32
    (light,), (orig,) = back.lights, scene.lights
    assert (light.kind, light.power_w, light.spot_size_rad, light.name) == ("SPOT", 300.0, 1.2, "Spot")
    np.testing.assert_allclose(light.direction, orig.direction)
    np.testing.assert_allclose(back.camera.projection, scene.camera.projection)
    assert (back.camera.width, back.camera.height) == (1920, 1080)


def test_camera_resize_keeps_horizontal_fov(tmp_path):
    scene = _scene()
    gpu_timing.save_scene(scene, tmp_path / "s")
    same_aspect = gpu_timing.load_scene(tmp_path / "s", (320, 180)).camera
    np.testing.assert_allclose(same_aspect.projection, scene.camera.projection)
    square = gpu_timing.load_scene(tmp_path / "s", (100, 100)).camera
    assert (square.width, square.height) == (100, 100)
    assert square.projection[1, 1] == square.projection[0, 0] == 1.0


def test_per_pass_sums_the_lpv_target_passes():
    runs = [{"total": 3.0, "gbuffer": 1.0, "lpv_inject": 0.5, "lpv_propagate": 1.0, "lpv_lookup": 0.5},
            {"total": 5.0, "gbuffer": 1.0, "lpv_inject": 1.0, "lpv_propagate": 2.0, "lpv_lookup": 1.0}]
    out = gpu_timing.per_pass(runs)
    assert out["lpv_inject+propagate+lookup"]["median"] == 3.0
    assert out["total"]["median"] == 4.0 and out["total"]["n"] == 2
    assert "vct_inject+pyramid" not in out


def test_configs_are_every_registry_row_and_the_gpu_extras():
    # Every method of the registry at its defaults and at each benchmark row, labels unique; each
    # settings dict builds the method it names (the same list of methods as everything else).
    from addon.engine import registry

    rows = gpu_timing.configs(360)
    labels = [label for label, _ in rows]
    assert len(labels) == len(set(labels))
    for spec in registry.METHODS:
        assert spec.name in labels  # the defaults
        for row in spec.bench:
            assert gpu_timing.row_label(spec.name, row) in labels
    for label, settings in rows:
        assert label.split("-")[0] == settings["gi"].method and settings["gi"].resolution == 360
    assert "vct-voxel_cells64-diffuse_cones6-gather_scale2" in labels
    # The viewport's defaults: auto sky rays are the filter there; direct's row of 8 rays keeps them.
    settings = dict(rows)
    assert all(s["rsm"].sky_rays == 0 for label, s in rows if label != "direct-sky_rays8")
    assert settings["direct-sky_rays8"]["rsm"].sky_rays == 8


def test_a_world_map_round_trips(tmp_path):
    # A sky-lit scene is timed with its radiance map: save_scene keeps it (float32), and a scene without
    # one loads without one.
    from dataclasses import replace

    sky = np.random.default_rng(0).uniform(0.0, 3.0, (8, 16, 3)).astype(np.float32)
    gpu_timing.save_scene(replace(_scene(), world_map=sky), tmp_path / "sky")
    gpu_timing.save_scene(_scene(), tmp_path / "plain")
    np.testing.assert_array_equal(gpu_timing.load_scene(tmp_path / "sky").world_map, sky)
    assert gpu_timing.load_scene(tmp_path / "plain").world_map is None


def test_every_methods_defaults_come_before_other_rows():
    rows = [(label, {}) for label in ("direct", "direct-resolution256", "rsm", "rsm-vpl_samples64")]
    order = [(scene, label) for scene, (label, _) in gpu_timing.run_order(["a", "b"], rows)]
    assert order == [("a", "direct"), ("b", "direct"), ("a", "rsm"), ("b", "rsm"), ("a", "direct-resolution256"),
                     ("b", "direct-resolution256"), ("a", "rsm-vpl_samples64"), ("b", "rsm-vpl_samples64")]


def test_a_spent_budget_starts_nothing_and_still_writes_the_tables(tmp_path):
    gpu_timing.save_scene(_scene(), tmp_path / "s")
    report = gpu_timing.run(tmp_path, tmp_path / "out", (32, 18), repeat=1, warmup=0, only_scenes=None,
                            only_configs=["direct-resolution256", "direct"], budget_s=0.0)
    assert report["skipped_for_budget"] == 2
    assert all(not entry["configs"] for entry in report["scenes"].values())
    assert (tmp_path / "out" / "timings.json").is_file() and (tmp_path / "out" / "timings.md").is_file()
