"""One module per GI method: which passes run, in which order. `get(name)` returns its class,
`create(backend, gi, rsm, lpv)` an instance with its configs."""

from __future__ import annotations

from ..errors import ConfigError


def get(name: str):
    from . import direct, lpv, rsm

    methods = {"direct": direct.DirectMethod, "rsm": rsm.RsmMethod, "lpv": lpv.LpvMethod}
    if name not in methods:
        raise ConfigError(f"unknown method {name!r}: known methods are {', '.join(sorted(methods))}")
    return methods[name]


def create(backend, gi, rsm, lpv=None):
    """The method `gi.method` with its configs: every method takes (gi, rsm); lpv also its LpvConfig
    (defaults when None)."""
    cls = get(gi.method)
    return cls(backend, gi, rsm, lpv) if gi.method == "lpv" else cls(backend, gi, rsm)
