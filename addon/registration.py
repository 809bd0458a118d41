"""Registers the Blender side of Bounce. Order matters: properties first (panels and operators read
scene.bounce), then operators and panels, then the viewport draw handler and the
live-update handlers; unregister runs the reverse so nothing is
left pointing at a class that is gone.

A module that adds a handler (bpy.app.handlers, draw handlers, timers) must remove it in its own
unregister(): a handler left behind survives disabling the add-on and runs stale code.
"""

from __future__ import annotations

from .. import operators, panels
from . import properties
from .bridge import live, viewport

# Handlers last: they read scene.bounce and draw what the panels configure.
_MODULES = (properties, operators, panels, viewport, live)


def register() -> None:
    done = []
    try:
        for module in _MODULES:
            module.register()
            done.append(module)
    except Exception:
        # A half-registered add-on cannot be disabled cleanly: undo what succeeded, then re-raise.
        for module in reversed(done):
            module.unregister()
        raise


def unregister() -> None:
    for module in reversed(_MODULES):
        module.unregister()
