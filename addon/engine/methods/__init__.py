"""One module per GI method: which passes run, in which order. The registry (engine/registry.py)
declares them; `get(name)` returns a method's class, `create(backend, gi, rsm, lpv, vct)` an instance
with its configs."""

from __future__ import annotations

from .. import registry


def get(name: str):
    return registry.method_class(name)


def create(backend, gi, rsm, lpv=None, vct=None):
    """The method `gi.method` with its configs: every method takes (gi, rsm); a method with a settings
    group of its own (registry: lpv, vct) also that group's config (its defaults when None)."""
    cls = get(gi.method)
    own = registry.get(gi.method).own_group
    if own is None:
        return cls(backend, gi, rsm)
    return cls(backend, gi, rsm, {"lpv": lpv, "vct": vct}[own])
