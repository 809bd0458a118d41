"""The command line's settings schema: one flag for every field of GIConfig, RsmConfig, LpvConfig and
VctConfig, generated from `config.limits()` so that a new field gets a flag and every default, range and
choice list is the dataclasses' own (the same as the scene settings in Blender).

A flag is the field's name with dashes (`--grid-cells`); a field name that several configs share is one
flag setting all of them (`--voxel-cells`: rsm's visibility grid and vct's grid are the same idea),
unless _PRIMARY gives one of them its own name. Values are checked while parsing, so a bad one exits 2
with one line naming the flag as it was typed (`error: --grid 3: out of range [8, 256]`).
"""

from __future__ import annotations

import argparse
import dataclasses
import re
from dataclasses import dataclass
from typing import Any

from ..engine import choice, config
from ..engine.config import DiffusionConfig, GIConfig, LpvConfig, RsmConfig, VctConfig
from ..engine.errors import ConfigError

CONFIGS = tuple(config.GROUPS.values())

# GIConfig and RsmConfig both have `resolution` and they are different ideas (image vs. shadow map).
_PRIMARY = {(RsmConfig, "resolution"): "--rsm-resolution",
            # lpv's near_steps defaults to half its grid, diffusion's to half its steps per bounce.
            (DiffusionConfig, "near_steps"): "--diffusion-near-steps"}

# The short spellings of earlier releases: the README, tests and benchmarks use them.
_ALIASES = {
    (GIConfig, "resolution"): ("--res",),
    (GIConfig, "samples"): ("--accumulate",),
    (RsmConfig, "resolution"): ("--rsm-res",),
    (LpvConfig, "grid_cells"): ("--grid",),
    (LpvConfig, "cell_size_m"): ("--cell-size",),
    (VctConfig, "diffuse_cones"): ("--cones",),
    (VctConfig, "offset_cells"): ("--cone-offset",),
}

# `--method auto`: the method and its settings chosen for a budget (engine/choice.py) after the scene
# is captured; the configs are built with the default method until then.
_EXTRA_CHOICES = {(GIConfig, "method"): (choice.AUTO,)}

_GIVEN = "_settings_given"  # namespace attribute: the dests the user typed a flag for


@dataclass(frozen=True)
class Setting:
    """One flag and the config fields it sets; limits are those of every field (intersected)."""

    flags: tuple[str, ...]  # primary first
    fields: tuple[tuple[type, str], ...]
    default: Any
    doc: str
    lo: float | None = None
    hi: float | None = None
    choices: tuple[str, ...] | None = None

    @property
    def dest(self) -> str:
        return self.flags[0].lstrip("-").replace("-", "_")

    @property
    def kind(self) -> type:
        return type(self.default)

    def parse(self, text: str):
        """The value of `text`, or ValueError with the reason (the caller names the flag)."""
        if self.choices is not None:
            if text not in self.choices:
                raise ValueError(f"must be one of {', '.join(self.choices)}")
            return text
        try:
            value = int(text) if self.kind is int else float(text)
        except ValueError:
            noun = "an integer" if self.kind is int else "a number"
            raise ValueError(f"must be {noun} in [{self.lo}, {self.hi}]") from None
        if not self.lo <= value <= self.hi:  # also refuses NaN
            raise ValueError(f"out of range [{self.lo}, {self.hi}]")
        return value

    def help(self) -> str:
        where = ", ".join(f"{cls.__name__}.{name}" for cls, name in self.fields)
        if self.choices is not None:
            limits = f"; one of {', '.join(self.choices)}"
        elif self.kind is bool:
            limits = ""
        else:
            limits = f"; range [{self.lo}, {self.hi}]"
        default = ("on" if self.default else "off") if self.kind is bool else self.default
        return f"{self.doc}{limits} (default: {default}; {where})".replace("%", "%%")


def _setting(fields: list[tuple[type, str]]) -> Setting:
    limits = [config.limits(cls)[name] for cls, name in fields]
    defaults = {repr(lim["default"]) for lim in limits}
    if len(defaults) > 1:  # one flag cannot have two defaults: give one field its own name in _PRIMARY
        raise AssertionError(f"fields {fields} share a flag but differ in default: {sorted(defaults)}")
    first = limits[0]
    cls, name = fields[0]
    flags = (_PRIMARY.get((cls, name), "--" + name.replace("_", "-")), *_ALIASES.get((cls, name), ()))
    bounds = {}
    if "min" in first:  # the range every field accepts
        bounds = {"lo": max(lim["min"] for lim in limits), "hi": min(lim["max"] for lim in limits)}
    choices = first.get("choices")
    if choices is not None:
        choices = (*choices, *_EXTRA_CHOICES.get((cls, name), ()))
    return Setting(flags, tuple(fields), first["default"], first["doc"], choices=choices, **bounds)


def _schema() -> tuple[Setting, ...]:
    groups: dict[str, list[tuple[type, str]]] = {}
    for cls in CONFIGS:
        for name in config.limits(cls):
            key = _PRIMARY.get((cls, name), name)
            groups.setdefault(key, []).append((cls, name))
    return tuple(_setting(fields) for fields in groups.values())


SETTINGS = _schema()


def _find(cls: type, name: str) -> Setting:
    return next(s for s in SETTINGS if (cls, name) in s.fields)


class _Checked(argparse.Action):
    """Parses and checks a value against its Setting; records that the user gave the flag."""

    def __init__(self, option_strings, dest, setting: Setting, **kwargs):
        self.setting = setting
        super().__init__(option_strings, dest, **kwargs)

    def __call__(self, parser, namespace, values, option_string=None):
        try:
            value = self.setting.parse(values)
        except ValueError as exc:
            parser.error(f"{option_string} {values}: {exc}")
        setattr(namespace, self.dest, value)
        _mark_given(namespace, self.dest)


class _CheckedBool(argparse.BooleanOptionalAction):
    """--flag / --no-flag; records that the user gave it."""

    def __call__(self, parser, namespace, values, option_string=None):
        super().__call__(parser, namespace, values, option_string)
        _mark_given(namespace, self.dest)


def _mark_given(namespace, dest: str) -> None:
    setattr(namespace, _GIVEN, getattr(namespace, _GIVEN, frozenset()) | {dest})


def given(args, dest: str) -> bool:
    """Whether the user typed the flag (any spelling) whose dest is `dest`."""
    return dest in getattr(args, _GIVEN, frozenset())


def _add(parser, setting: Setting) -> None:
    common = {"dest": setting.dest, "default": setting.default, "help": setting.help()}
    if setting.kind is bool:
        parser.add_argument(*setting.flags, action=_CheckedBool, **common)
        return
    metavar = "{" + ",".join(setting.choices) + "}" if setting.choices else setting.kind.__name__.upper()
    parser.add_argument(*setting.flags, action=_Checked, setting=setting, metavar=metavar, **common)


def add_config_flags(parser) -> None:
    """A flag per config field (see module docstring), grouped by config."""
    for cls in CONFIGS:
        group = parser.add_argument_group(f"{cls.__name__} (defaults = the scene settings in Blender)",
                                          (cls.__doc__ or "").strip().splitlines()[0])
        for setting in SETTINGS:
            if setting.fields[0][0] is cls:
                _add(group, setting)


def add_field_flag(parser, cls: type, name: str, *flags: str, default=None, doc: str | None = None) -> None:
    """One flag checked against a config field's limits, for commands that do not build that config
    (reference's --res, screenshot's --method): the flag, default and help may be the command's own."""
    setting = _find(cls, name)
    _add(parser, dataclasses.replace(setting, flags=flags or setting.flags, doc=doc or setting.doc,
                                     default=setting.default if default is None else default))


def flag_name(cls: type, name: str) -> str:
    """The primary flag of a config field."""
    return _find(cls, name).flags[0]


def configs(args, **overrides) -> dict:
    """{group: config} (config.settings' form) from parsed args; overrides: {dest: value} replacing
    parsed values. `--method auto` builds the default method's configs (budget() says what to choose)."""
    values = {cls: {} for cls in CONFIGS}
    for setting in SETTINGS:
        value = overrides.get(setting.dest, getattr(args, setting.dest))
        if (GIConfig, "method") in setting.fields and value == choice.AUTO:
            value = GIConfig().method
        for cls, name in setting.fields:
            values[cls][name] = value
    return {group: cls(**values[cls]) for group, cls in config.GROUPS.items()}


def add_budget_flags(parser) -> None:
    """--error-budget / --time-budget, read with --method auto (engine/choice.py)."""
    group = parser.add_argument_group("choice (with --method auto)", "the method and settings chosen for the scene")
    group.add_argument("--error-budget", type=float, metavar="E",
                       help="choose the fastest setting expected within rel_rmse_8 E of a path tracer (0 < E <= 2)")
    group.add_argument("--time-budget", type=float, metavar="MS",
                       help="choose the most accurate setting expected within MS milliseconds per update")


def budget(args) -> dict | None:
    """The budget of `--method auto` ({"error_budget": E} or {"time_budget_ms": T}), None without auto;
    ConfigError naming the flags when they do not go together."""
    auto = getattr(args, "method", None) == choice.AUTO
    error, time_ms = getattr(args, "error_budget", None), getattr(args, "time_budget", None)
    if not auto:
        if error is not None or time_ms is not None:
            raise ConfigError("--error-budget and --time-budget choose a method: give them with --method auto")
        return None
    if (error is None) == (time_ms is None):
        raise ConfigError("--method auto needs exactly one of --error-budget E and --time-budget MS")
    if error is not None:
        if not 0.0 < error <= 2.0:  # also refuses NaN
            raise ConfigError(f"--error-budget {error:g}: out of range (0, 2]")
        return {"error_budget": error}
    if not 0.0 < time_ms < float("inf"):
        raise ConfigError(f"--time-budget {time_ms:g}: must be a positive number of milliseconds")
    return {"time_budget_ms": time_ms}


def in_flag_terms(message: str) -> str:
    """A ConfigError's text with `Config.field` names replaced by their flags (a check made after
    parsing, e.g. a method's bounce limit, then still names what the user can change)."""
    for setting in SETTINGS:
        for cls, name in setting.fields:
            message = re.sub(rf"\b{cls.__name__}\.{name}\b", setting.flags[0], message)
    return message


def check_bounces(gi: GIConfig) -> None:
    """Refuse more bounces than the method computes, before any file is opened or written."""
    from ..engine import methods

    most = getattr(methods.get(gi.method), "max_bounces", None)
    if most is not None and gi.bounces > most:
        raise ConfigError(f"{flag_name(GIConfig, 'bounces')} {gi.bounces}: method {gi.method} computes at most "
                          f"{most} bounce(s)")
