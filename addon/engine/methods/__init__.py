"""One module per GI method: which passes run, in which order. `get(name)` returns its class,
`create(backend, gi, rsm, lpv, vct)` an instance with its configs."""

from __future__ import annotations

from ..errors import ConfigError


def get(name: str):
    from . import direct, lpv, rsm, vct

    methods = {"direct": direct.DirectMethod, "rsm": rsm.RsmMethod, "lpv": lpv.LpvMethod, "vct": vct.VctMethod}
    if name not in methods:
        raise ConfigError(f"unknown method {name!r}: known methods are {', '.join(sorted(methods))}")
    return methods[name]


def create(backend, gi, rsm, lpv=None, vct=None):
    """The method `gi.method` with its configs: every method takes (gi, rsm); lpv also its LpvConfig,
    vct its VctConfig (defaults when None)."""
    cls = get(gi.method)
    own = {"lpv": lpv, "vct": vct}
    return cls(backend, gi, rsm, own[gi.method]) if gi.method in own else cls(backend, gi, rsm)
