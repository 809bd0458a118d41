"""One module per GI method: which passes run, in which order. The registry (engine/registry.py)
declares them; `get(name)` returns a method's class, `create(backend, settings)` an instance."""

from __future__ import annotations

from .. import registry
from ..config import settings as complete


def get(name: str):
    return registry.method_class(name)


def create(backend, settings: dict):
    """The method settings["gi"].method built from {group: config} (config.settings; missing groups
    take their defaults): every method takes the gi and rsm configs, a method with a settings group of
    its own (registry) also those groups' configs, in the order it reads them."""
    settings = complete(**settings)
    spec = registry.get(settings["gi"].method)
    own = tuple(settings[group] for group in spec.own_groups)
    return get(spec.name)(backend, settings["gi"], settings["rsm"], *own)
