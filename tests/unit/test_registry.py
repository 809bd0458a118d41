"""The method registry is the one list of methods: everything else derives from it, and it agrees
with the classes, the configs and the command line."""

import json

import pytest

from addon import cli
from addon.engine import config, methods, registry


def test_config_method_choices_are_the_registry():
    assert config.limits(config.GIConfig)["method"]["choices"] == registry.NAMES
    assert registry.NAMES == ("direct", "rsm", "lpv", "vct", "probes", "diffusion", "gather")  # shipped, in menu order


@pytest.mark.parametrize("spec", registry.METHODS, ids=lambda s: s.name)
def test_each_class_takes_its_declaration(spec):
    cls = methods.get(spec.name)
    assert (cls.name, cls.products, cls.max_bounces) == (spec.name, spec.products, spec.max_bounces)
    assert "albedo" in spec.products
    assert spec.own_group is None or spec.own_group in config.GROUPS


@pytest.mark.parametrize("spec", registry.METHODS, ids=lambda s: s.name)
def test_reads_name_real_settings(spec):
    for entry in spec.reads:
        group, _, field = entry.partition(".")
        assert group in config.GROUPS, entry
        assert field == "*" or field in config.limits(config.GROUPS[group]), entry


def test_every_setting_is_read_by_some_method():
    unread = [f"{g}.{f}" for g, cls in config.GROUPS.items() for f in config.limits(cls)
              if not any(m.reads_setting(g, f) for m in registry.METHODS)]
    assert unread == []


def test_unknown_method_is_one_clear_error():
    with pytest.raises(config.ConfigError, match="unknown method 'magic': known methods are direct, rsm"):
        registry.get("magic")


def test_create_fills_missing_groups_with_defaults():
    # methods.create takes {group: config}; a group left out takes its defaults, an unknown one is refused.
    with pytest.raises(config.ConfigError, match="unknown settings group"):
        config.settings(photons=config.GIConfig())
    with pytest.raises(config.ConfigError, match="takes a LpvConfig"):
        config.settings(lpv=config.VctConfig())
    full = config.settings(gi=config.GIConfig(method="lpv"))
    assert full["lpv"] == config.LpvConfig() and full["gi"].method == "lpv"


def test_methods_command_lists_every_method_and_setting(capsys):
    assert cli.main(["methods", "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert [m["name"] for m in d["methods"]] == list(registry.NAMES)
    expected = [f"{g}.{f}" for g, cls in config.GROUPS.items() for f in config.limits(cls)]
    assert [s["setting"] for s in d["settings"]] == expected
    by = {s["setting"]: s for s in d["settings"]}
    assert by["lpv.grid_cells"] == {
        "setting": "lpv.grid_cells", "flag": "--grid-cells", "type": "int", "default": 32, "unit": "cells",
        "description": config.limits(config.LpvConfig)["grid_cells"]["doc"], "read_by": ["lpv"], "range": [8, 256]}
    assert by["lpv.cell_size_m"]["unit"] == "m" and by["gi.method"]["choices"] == list(registry.NAMES)
    assert cli.main(["methods"]) == 0
    assert "rsm.vpl_samples" in capsys.readouterr().out
