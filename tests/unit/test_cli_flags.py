"""The command line's settings schema (addon/commands/_settings.py): a flag for every config field, the
configs' own defaults and limits, the short spellings of earlier releases, and --help that says them."""

import pytest

from addon.cli import build_parser
from addon.commands import _settings
from addon.engine import config
from addon.engine.config import (
    DiffusionConfig,
    GatherConfig,
    GIConfig,
    LpvConfig,
    ProbesConfig,
    RsmConfig,
    VctConfig,
)

CONFIG_COMMANDS = ("render", "bake")  # the commands that build all four configs


def parse(command, *flags):
    return build_parser().parse_args([command, "scene.blend", "--out", "o", *flags])


def every_field():
    return [(cls, name) for cls in _settings.CONFIGS for name in config.limits(cls)]


def other_value(setting):
    """A valid value that is not the default, and the command-line words that set it."""
    if setting.kind is bool:
        flag = setting.flags[0] if not setting.default else "--no-" + setting.flags[0][2:]
        return not setting.default, [flag]
    if setting.choices:
        value = next(c for c in setting.choices if c != setting.default)
    else:
        value = setting.kind(setting.hi if setting.default != setting.hi else setting.lo)
    return value, [setting.flags[0], str(value)]


def test_the_schema_covers_the_four_configs():
    assert set(_settings.CONFIGS) == {GIConfig, RsmConfig, LpvConfig, VctConfig, ProbesConfig, DiffusionConfig,
                                      GatherConfig}


@pytest.mark.parametrize("field", every_field(), ids=lambda f: f"{f[0].__name__}.{f[1]}")
@pytest.mark.parametrize("command", CONFIG_COMMANDS)
def test_every_config_field_has_a_flag_that_sets_it(command, field):
    # Iterates config.limits(): a field added to a config without a working flag fails here.
    cls, name = field
    setting = next(s for s in _settings.SETTINGS if field in s.fields)
    value, words = other_value(setting)
    configs = {type(c): c for c in _settings.configs(parse(command, *words)).values()}
    assert getattr(configs[cls], name) == value


@pytest.mark.parametrize("command", CONFIG_COMMANDS)
def test_defaults_are_the_configs_own(command):
    assert _settings.configs(parse(command)) == config.settings()


def test_primary_flags_are_the_field_names():
    flags = {s.flags[0] for s in _settings.SETTINGS}
    assert {"--grid-cells", "--diffuse-cones", "--offset-cells", "--cell-size-m", "--shadow-bias-texels",
            "--resolution", "--rsm-resolution", "--voxel-cells", "--bounces"} <= flags


@pytest.mark.parametrize(("words", "field", "value"), [
    (["--res", "64"], (GIConfig, "resolution"), 64),
    (["--rsm-res", "128"], (RsmConfig, "resolution"), 128),
    (["--grid", "16"], (LpvConfig, "grid_cells"), 16),
    (["--cones", "6"], (VctConfig, "diffuse_cones"), 6),
    (["--cone-offset", "2.5"], (VctConfig, "offset_cells"), 2.5),
    (["--cell-size", "0.25"], (LpvConfig, "cell_size_m"), 0.25),
    (["--iterations", "8"], (LpvConfig, "iterations"), 8),
    (["--voxel-cells", "32"], (RsmConfig, "voxel_cells"), 32),
    (["--voxel-cells", "32"], (VctConfig, "voxel_cells"), 32),
])
def test_short_spellings_still_work(words, field, value):
    configs = {type(c): c for c in _settings.configs(parse("render", *words)).values()}
    assert getattr(configs[field[0]], field[1]) == value


def test_a_shared_flag_takes_the_range_both_fields_accept():
    setting = next(s for s in _settings.SETTINGS if (VctConfig, "voxel_cells") in s.fields)
    assert (RsmConfig, "voxel_cells") in setting.fields
    rsm, vct = config.limits(RsmConfig)["voxel_cells"], config.limits(VctConfig)["voxel_cells"]
    assert (setting.lo, setting.hi) == (max(rsm["min"], vct["min"]), min(rsm["max"], vct["max"]))


def test_help_shows_choices_defaults_and_ranges(capsys):
    with pytest.raises(SystemExit):
        build_parser().parse_args(["render", "--help"])
    text = " ".join(capsys.readouterr().out.split())  # argparse wraps lines
    assert "--grid-cells INT, --grid INT" in text
    assert "range [8, 256] (default: 32; LpvConfig.grid_cells, DiffusionConfig.grid_cells)" in text
    assert "--visibility {none,voxel}" in text and "one of none, voxel (default: none;" in text
    assert f"(default: {GIConfig().method}; GIConfig.method)" in text
    assert "--far-field, --no-far-field" in text
    assert "(default: on; LpvConfig.far_field, DiffusionConfig.far_field)" in text


def test_render_and_bake_share_the_method_default():
    # bake's own --method rsm and --visibility voxel defaults are gone: both follow the configs.
    assert parse("bake").method == parse("render").method == GIConfig().method
    assert parse("bake").visibility == RsmConfig().visibility


def test_config_field_names_in_messages_become_flags():
    assert _settings.in_flag_terms("LpvConfig.grid_cells = 3: out of range") == "--grid-cells = 3: out of range"
    assert _settings.in_flag_terms("RsmConfig.voxel_offset_cells") == "--voxel-offset-cells"
    assert _settings.in_flag_terms("RsmConfig.resolution") == "--rsm-resolution"

