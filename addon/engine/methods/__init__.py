"""One module per GI method: which passes run, in which order. `get(name)` returns its class."""

from __future__ import annotations

from ..errors import ConfigError


def get(name: str):
    from . import direct, rsm

    methods = {"direct": direct.DirectMethod, "rsm": rsm.RsmMethod}
    if name not in methods:
        raise ConfigError(f"unknown method {name!r}: known methods are {', '.join(sorted(methods))}")
    return methods[name]
