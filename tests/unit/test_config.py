"""Config validation: every bad value names the field and its allowed range."""

import math

import pytest

from addon.engine.config import GIConfig, RsmConfig, limits
from addon.engine.errors import ConfigError


def test_defaults_are_valid():
    assert GIConfig().method == "rsm"
    assert RsmConfig().resolution == 256


@pytest.mark.parametrize(
    ("cls", "field", "value", "needle"),
    [
        (GIConfig, "method", "magic", "GIConfig.method = 'magic': must be one of direct, rsm"),
        (GIConfig, "bounces", 0, "GIConfig.bounces = 0: out of range [1, 8]"),
        (GIConfig, "bounces", 2.5, "must be an integer"),
        (GIConfig, "resolution", True, "must be a number"),
        (RsmConfig, "shadow_bias_texels", math.nan, "out of range [0.0, 8.0]"),
        (RsmConfig, "resolution", 1e9, "out of range [16, 4096]"),
    ],
)
def test_bad_value_names_field_and_range(cls, field, value, needle):
    with pytest.raises(ConfigError) as info:
        cls(**{field: value})
    assert needle in str(info.value)


def test_integral_float_becomes_int():
    assert GIConfig(bounces=2.0).bounces == 2
    assert isinstance(GIConfig(bounces=2.0).bounces, int)


def test_unknown_key_is_refused():
    with pytest.raises(ConfigError, match="unknown field.*grid_size"):
        GIConfig.from_dict({"grid_size": 3})


def test_frozen():
    with pytest.raises(AttributeError):
        GIConfig().bounces = 3


def test_limits_expose_what_properties_mirror():
    lim = limits(RsmConfig)["resolution"]
    assert (lim["default"], lim["min"], lim["max"]) == (256, 16, 4096)
    assert limits(GIConfig)["method"]["choices"] == ("direct", "rsm", "lpv", "vct", "probes", "diffusion", "gather")
