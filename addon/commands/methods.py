"""`python -m addon methods [--json]`: the method registry and every setting, from their declarations.

For each method: what it computes, its products, its bounce limit and its benchmark rows. For each
setting (every field of config.GROUPS): its command-line flag, type, default, range or choices, unit,
description, and the methods that read it (registry `reads`), so a user sees what a setting changes
without reading code.
"""

from __future__ import annotations

import json

from ..engine import config, registry
from ._settings import flag_name

NAME = "methods"
HELP = "list the GI methods and every setting (type, default, range, unit, which methods read it)"

# Field-name suffix -> unit (config fields carry their unit in their name, docs/ARCHITECTURE.md).
_UNITS = {"m": "m", "rad": "rad", "ms": "ms", "mb": "MB", "texels": "texels", "cells": "cells"}


def add_arguments(p) -> None:
    p.add_argument("--json", action="store_true", help="one JSON object instead of text")


def unit(field: str) -> str | None:
    return _UNITS.get(field.rsplit("_", 1)[-1]) if "_" in field else None


def describe() -> dict:
    """The registry and the settings as plain data (what --json prints)."""
    methods = [{"name": m.name, "summary": m.summary, "products": list(m.products), "max_bounces": m.max_bounces,
                "settings_group": m.own_group, "bench": list(m.bench)} for m in registry.METHODS]
    settings = []
    for group, cls in config.GROUPS.items():
        for field, lim in config.limits(cls).items():
            entry = {"setting": f"{group}.{field}", "flag": flag_name(cls, field),
                     "type": type(lim["default"]).__name__, "default": lim["default"], "unit": unit(field),
                     "description": lim.get("doc", ""),
                     "read_by": [m.name for m in registry.METHODS if m.reads_setting(group, field)]}
            if "choices" in lim:
                entry["choices"] = list(lim["choices"])
            elif "min" in lim:
                entry["range"] = [lim["min"], lim["max"]]
            settings.append(entry)
    return {"methods": methods, "settings": settings}


def _text(d: dict) -> str:
    lines = ["Methods:"]
    for m in d["methods"]:
        lines.append(f"  {m['name']:8s} {m['summary']}")
        lines.append(f"  {'':8s} products {', '.join(m['products'])}; up to {m['max_bounces']} bounce(s)")
    lines += ["", "Settings (flag, type, default, range or choices, unit; read by):"]
    for s in d["settings"]:
        limits = ("one of " + ", ".join(s["choices"]) if "choices" in s
                  else f"[{s['range'][0]}, {s['range'][1]}]" if "range" in s else "")
        unit_text = f" {s['unit']}" if s["unit"] else ""
        lines.append(f"  {s['setting']:26s} {s['flag']:22s} {s['type']:5s} {s['default']!s:11s} {limits}{unit_text};"
                     f" read by {', '.join(s['read_by']) or 'none'}")
        lines.append(f"  {'':26s} {s['description']}")
    return "\n".join(lines)


def run(args) -> int:
    d = describe()
    print(json.dumps(d, indent=1) if args.json else _text(d))
    return 0
