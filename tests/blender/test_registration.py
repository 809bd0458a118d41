"""Registering the repository as a Blender add-on: round trips leave nothing behind, settings mirror the
engine's configs and survive a save and reload.

The repository root is imported as a package named `bounce` (through a symlink), as Blender imports it:
that is what makes the relative imports between addon/, operators/ and panels/ resolve.
"""

from __future__ import annotations

import dataclasses
from pathlib import Path

import pytest

bpy = pytest.importorskip("bpy")

ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture
def registered(bounce, fresh_blend):
    bounce.register()
    yield bounce
    bounce.unregister()


def _handler_counts() -> dict[str, int]:
    handlers = bpy.app.handlers
    return {name: len(getattr(handlers, name)) for name in dir(handlers) if isinstance(getattr(handlers, name), list)}


def _operator_registered() -> bool:
    try:
        bpy.ops.bounce.report_renderer.get_rna_type()
    except KeyError:
        return False
    return True


def _all_classes(bounce) -> list[type]:
    from bounce.addon import properties

    return [*properties.classes, *bounce.operators.classes, *bounce.panels.classes]


def test_register_unregister_twice_leaves_nothing_behind(bounce, fresh_blend):
    before = _handler_counts()
    assert "load_post" in before and "depsgraph_update_post" in before
    classes = _all_classes(bounce)
    # a property group per settings group (config.GROUPS) and one for them all, 4 operators
    # (report_renderer, bake, choose, capture_world), 3 panels (main, its viewport sub-panel, the sidebar tab)
    from addon.engine import config

    assert len(classes) == len(config.GROUPS) + 1 + 4 + 3
    for _ in range(2):
        bounce.register()
        try:
            assert isinstance(bpy.context.scene.bounce, bpy.types.PropertyGroup)
            assert _operator_registered()
            assert all(cls.is_registered for cls in classes)
        finally:
            bounce.unregister()
        assert not hasattr(bpy.types.Scene, "bounce")
        assert not _operator_registered()
        assert not any(cls.is_registered for cls in classes)
        assert _handler_counts() == before


def test_no_addon_preferences(registered):
    # The backend and memory-budget preferences were never read: removed rather than left as dead
    # settings. An AddonPreferences class would be found by bl_idname == the package name.
    assert not any(issubclass(cls, bpy.types.AddonPreferences)
                   for cls in bpy.types.AddonPreferences.__subclasses__() if cls.bl_idname == "bounce")


def test_report_renderer_operator_finishes(registered, capfd):
    assert bpy.ops.bounce.report_renderer() == {"FINISHED"}
    # Background Blender prints reports to stdout as "Info: <message>".
    lines = [line for line in capfd.readouterr().out.splitlines() if line.startswith("Info: ")]
    assert lines and len(lines[-1]) > len("Info: ")


def _mismatches(group_rna, config_cls, limits_fn) -> list[str]:
    """What differs between a PropertyGroup's RNA and a config dataclass's fields."""
    problems = []
    for name, spec in limits_fn(config_cls).items():
        if name not in group_rna.properties:
            problems.append(f"{name}: no property")
            continue
        prop = group_rna.properties[name]
        if "choices" in spec:
            got = (prop.type, [i.identifier for i in prop.enum_items], prop.default)
            want = ("ENUM", list(spec["choices"]), spec["default"])
        elif isinstance(spec["default"], bool):
            got = (prop.type, prop.default)
            want = ("BOOLEAN", spec["default"])
        else:
            # Blender floats are 32-bit: compare to float32 precision (rel 1e-6), ints exactly.
            got = (prop.type, prop.default, prop.hard_min, prop.hard_max)
            want = ("INT" if isinstance(spec["default"], int) else "FLOAT", spec["default"], spec["min"], spec["max"])
            if got[0] == "FLOAT" == want[0]:
                got = (got[0], *(round(v, 6) for v in got[1:]))
                want = (want[0], *(round(v, 6) for v in want[1:]))
        if got != want:
            problems.append(f"{name}: property {got} != config {want}")
    return problems


def test_properties_mirror_every_config_field(registered):
    from bounce.addon.engine import config
    from bounce.addon.properties import CONFIGS

    assert set(CONFIGS.values()) >= {config.GIConfig, config.RsmConfig, config.LpvConfig}
    for attr, cls in CONFIGS.items():
        group_rna = getattr(bpy.context.scene.bounce, attr).bl_rna
        assert _mismatches(group_rna, cls, config.limits) == []


def test_mirror_check_catches_a_config_change(registered):
    from bounce.addon.engine import config

    @dataclasses.dataclass(frozen=True)
    class Drifted(config.GIConfig):
        bounces: int = dataclasses.field(default=2, metadata={"min": 1, "max": 16})
        depth_m: float = dataclasses.field(default=0.5, metadata={"min": 0.0, "max": 1.0})

    problems = _mismatches(bpy.context.scene.bounce.gi.bl_rna, Drifted, config.limits)
    assert problems == [
        "bounces: property ('INT', 1, 1, 8) != config ('INT', 2, 1, 16)",
        "depth_m: no property",
    ]

    @dataclasses.dataclass(frozen=True)
    class DriftedBool(config.LpvConfig):
        geometry_volume: bool = dataclasses.field(default=False, metadata={"doc": ""})

    problems = _mismatches(bpy.context.scene.bounce.lpv.bl_rna, DriftedBool, config.limits)
    assert problems == ["geometry_volume: property ('BOOLEAN', True) != config ('BOOLEAN', False)"]


def test_defaults_give_default_configs(registered):
    from bounce.addon.engine import config
    from bounce.addon.properties import to_config

    assert to_config(bpy.context.scene.bounce) == config.settings()


def test_settings_survive_save_and_reload(registered, tmp_path):
    from bounce.addon.properties import to_config

    settings = bpy.context.scene.bounce
    settings.enabled = True
    settings.gi.method = "rsm"
    settings.gi.bounces = 3
    settings.rsm.resolution = 512
    settings.rsm.shadow_bias_texels = 0.05
    settings.lpv.variant = "improved"
    settings.lpv.geometry_volume = True
    path = tmp_path / "settings.blend"
    bpy.ops.wm.save_as_mainfile(filepath=str(path))
    bpy.ops.wm.read_factory_settings(use_empty=True)
    assert bpy.context.scene.bounce.gi.bounces == 1

    bpy.ops.wm.open_mainfile(filepath=str(path))
    settings = bpy.context.scene.bounce
    assert settings.enabled
    configs = to_config(settings)
    gi, rsm, lpv = configs["gi"], configs["rsm"], configs["lpv"]
    assert (gi.method, gi.bounces, rsm.resolution) == ("rsm", 3, 512)
    assert (lpv.variant, lpv.geometry_volume) == ("improved", True)
    assert rsm.shadow_bias_texels == 0.05  # exactly: to_config undoes Blender's float32 rounding


class _RecordingLayout:
    """Stands in for UILayout (there is no UI in background mode): records what a panel draws, and
    which operators it draws greyed out (`active` False on the layout or one it was made from)."""

    def __init__(self, drawn, greyed=None, parent=None):
        self.drawn, self.greyed, self.parent = drawn, greyed if greyed is not None else [], parent
        self.active = True

    def _greyed(self) -> bool:
        return not self.active or (self.parent is not None and self.parent._greyed())

    def column(self, **_kwargs):
        return _RecordingLayout(self.drawn, self.greyed, self)

    box = row = column

    def label(self, **_kwargs):
        pass

    def prop(self, data, name, **_kwargs):
        assert name in data.bl_rna.properties, name
        self.drawn.append(name)

    def operator(self, idname, **_kwargs):
        self.drawn.append(idname)
        if self._greyed():
            self.greyed.append(idname)


def test_panel_draws_what_the_method_reads(registered):
    from bounce.addon.engine import config, registry
    from bounce.panels.main import BOUNCE_PT_main

    def drawn_settings():
        drawn = []
        panel = type("Panel", (), {"layout": _RecordingLayout(drawn)})()
        BOUNCE_PT_main.draw_header(panel, bpy.context)
        BOUNCE_PT_main.draw(panel, bpy.context)
        return drawn

    shown = set()
    for spec in registry.METHODS:
        bpy.context.scene.bounce.gi.method = spec.name
        expected = [name for group, cls in config.GROUPS.items() for name in config.limits(cls)
                    if spec.reads_setting(group, name)]
        assert drawn_settings() == ["enabled", *expected, "error_budget", "bounce.choose", "bounce.report_renderer",
                                    "bounce.bake"], spec.name
        shown |= {(group, name) for group, cls in config.GROUPS.items() for name in config.limits(cls)
                  if spec.reads_setting(group, name)}
    # Written out for one case: `direct` has no VPL gather, so no VPL samples and no LPV or VCT group.
    bpy.context.scene.bounce.gi.method = "direct"
    assert drawn_settings() == ["enabled", "method", "resolution", "resolution", "shadow_bias_texels", "sky_rays",
                                "error_budget", "bounce.choose", "bounce.report_renderer", "bounce.bake"]
    # Every setting is shown under some method: none is unreachable from the UI (the command line's
    # flags: tests/unit/test_cli_flags.py; the defaults: test_properties_mirror_every_config_field).
    every = {(group, name) for group, cls in config.GROUPS.items() for name in config.limits(cls)}
    assert every - shown == set()


def test_bake_button_is_not_greyed_while_the_overlay_is_off(registered):
    # A bake does not need the overlay: only the settings are drawn greyed (still editable) when it is off.
    from bounce.panels.main import BOUNCE_PT_main

    layout = _RecordingLayout([])
    bpy.context.scene.bounce.enabled = False
    BOUNCE_PT_main.draw(type("Panel", (), {"layout": layout})(), bpy.context)
    assert "bounce.bake" in layout.drawn and layout.greyed == []
