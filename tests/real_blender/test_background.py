"""`blender --background` (Debian's 4.3 binary): install from the zip, register/unregister, the Bake
operator with the defaults and every method, save and reload."""

from __future__ import annotations

import pytest

from addon.engine.registry import NAMES as METHODS


def test_blender_is_a_real_4x_binary(installed):
    # The point of the tier: not the bpy module (5.0.1) the rest of the suite runs on.
    major, minor = (int(x) for x in installed["blender"].split(".")[:2])
    assert (major, minor) >= (4, 2) and major < 5, installed["blender"]


def test_install_enables_and_round_trips(installed):
    assert installed["install"] == ["FINISHED"]
    assert installed["enabled_after_install"] and installed["scene_settings"]
    for i, cycle in enumerate(installed["cycles"]):
        if i % 2 == 0:  # after a disable: nothing of Bounce left, handlers as before the install
            assert cycle == {"enabled": False, "scene_settings": False, "handlers_restored": True}
        else:
            assert cycle == {"enabled": True, "scene_settings": True}
    assert installed["default_method"] == "rsm"  # an indirect method: the defaults show bounce light


def test_ui_paths_do_not_import_openimageio(installed):
    # Debian's Blender has no OpenImageIO module and the extension does not ship one: the viewport
    # and bake operator must work without it (the CLI's venv has it).
    assert installed["blender_has_openimageio"] is False
    assert installed["openimageio_imported"] is False


@pytest.fixture(scope="module")
def baked(real, cornell_blend):
    inside, _ = real.path("baked.blend")
    result = real.script("bake.py", [inside], blend=cornell_blend)
    return result, inside


def test_bake_with_defaults_and_overlay_off(baked):
    result, _ = baked
    assert result["overlay_enabled"] is False and result["default_method"] == "rsm"
    assert result["openimageio_imported"] is False


@pytest.mark.parametrize("method", [*METHODS, "diffusion-single-field"])
def test_every_method_bakes_light(baked, method):
    entry = baked[0]["methods"][method]
    assert entry["status"] == ["FINISHED"] and entry["vertex_colors_status"] == ["FINISHED"]
    for name, stats in entry["images"].items():
        assert stats["size"] == [32, 32] and stats["finite"], (name, stats)
        assert stats["packed"] and stats["users"] >= 1, (name, stats)  # kept by the .blend
        assert stats["min"] >= 0.0, (name, stats)  # no negative light
    # The spot lights the floor directly and the walls light it indirectly: every method bakes light
    # into it (the back wall's indirect light at 16 LPV cells may be faint, so only the floor is bounded).
    assert entry["images"]["Floor"]["max"] > 0.01, entry
    # The floor's four corners lie outside the spot's cone (no direct light there) but receive light
    # from the walls.
    assert entry["vertex_colors_max"] > 0.0 if method != "direct" else entry["vertex_colors_max"] == 0.0, entry


def test_baked_images_survive_save_and_reload(real, baked):
    result, blend = baked
    reloaded = real.script("reload.py", [], blend=blend)
    last = result["methods"][METHODS[-1]]["images"]
    assert set(reloaded["images"]) == {"Floor_bounce_indirect", "BackWall_bounce_indirect",
                                       "Floor_bounce_direct", "BackWall_bounce_direct"}
    for obj, stats in last.items():
        again = reloaded["images"][f"{obj}_bounce_indirect"]
        assert again["packed"] and again["size"] == stats["size"]
        # The packed EXR is read back as written, up to half-float rounding (Blender may pack float
        # images as half EXR: 2^-11 relative).
        assert again["mean"] == pytest.approx(stats["mean"], rel=1e-3, abs=1e-6)
        assert again["max"] == pytest.approx(stats["max"], rel=1e-3, abs=1e-6)
    # The scene settings are saved in the .blend too.
    assert reloaded["method"] == METHODS[-1] and reloaded["lpv_grid_cells"] == 16
