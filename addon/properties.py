"""Scene settings: `scene.bounce`, generated from the engine's config dataclasses.

GIConfig and RsmConfig both have a `resolution`, so each config gets its own group
(`scene.bounce.gi.resolution`, `scene.bounce.rsm.resolution`, `scene.bounce.lpv.grid_cells`) and keeps
the dataclass's field names.
Names, defaults, limits and enum items come from `config.limits()`, so the UI cannot drift from what
the engine validates.
"""

from __future__ import annotations

import bpy
from bpy.props import BoolProperty, EnumProperty, FloatProperty, IntProperty, PointerProperty, StringProperty

from .engine import config

# Group attribute on scene.bounce -> the config it mirrors (the panels show, per method, the fields the
# registry says it reads).
CONFIGS = config.GROUPS


_ACRONYMS = {"vpl", "rsm", "lpv", "vct", "sh"}
_UNITS = {"mb": "MB", "ms": "ms"}  # shown in the label; lengths and angles get Blender's own units
# Config names carry their unit as a suffix: a length (`cell_size_m`) or an angle (`_rad`) becomes a
# property with Blender's unit, so it displays and edits in the scene's units (1 m, 90°).
_BLENDER_UNITS = {"m": {"subtype": "DISTANCE", "unit": "LENGTH"}, "rad": {"subtype": "ANGLE", "unit": "ROTATION"}}


def _label(name: str) -> str:
    # `cell_size_m` -> "Cell Size" (a length property), `budget_mb` -> "Budget (MB)".
    words = name.split("_")
    suffix = words[-1] if len(words) > 1 else None
    unit = _UNITS.get(suffix)
    if unit or suffix in _BLENDER_UNITS:
        words = words[:-1]
    label = " ".join(w.upper() if w in _ACRONYMS else w.title() for w in words)
    return f"{label} ({unit})" if unit else label


def _property(name: str, spec: dict):
    label = _label(name)
    doc = spec.get("doc", "")
    units = _BLENDER_UNITS.get(name.rsplit("_", 1)[-1], {}) if "_" in name else {}
    if "choices" in spec:
        items = [(c, c.replace("-", " ").title(), "") for c in spec["choices"]]
        return EnumProperty(name=label, description=doc, items=items, default=spec["default"])
    default = spec["default"]
    if isinstance(default, bool):
        return BoolProperty(name=label, description=doc, default=default)
    if isinstance(default, int):
        return IntProperty(name=label, description=doc, default=default, min=spec["min"], max=spec["max"])
    if isinstance(default, float):
        return FloatProperty(
            name=label, description=doc, default=default, min=spec["min"], max=spec["max"], precision=4, **units
        )
    raise TypeError(f"no Blender property for config field {name!r} (default {default!r}): add one here")


def _group(attr: str, cls) -> type:
    annotations = {name: _property(name, spec) for name, spec in config.limits(cls).items()}
    return type(f"BOUNCE_PG_{attr}", (bpy.types.PropertyGroup,), {"__annotations__": annotations})


_GROUPS = {attr: _group(attr, cls) for attr, cls in CONFIGS.items()}


# Quality presets: RSM side, VPLs per pixel, their visibility and the sky's exact rays. The labels say
# what they cost and gain; figures in benchmarks/REPORT.md (see panels/viewport.py for where each comes
# from). (RSM resolution, VPLs per pixel, VPL visibility, sky rays); the labels quote method rsm on the
# Cornell box from benchmarks/REPORT.md (128 px, one bounce, vs Cycles 512 spp; times on the CPU
# rasteriser llvmpipe, a GPU is far faster) and the direct light of window-sky (docs/DIRECT.md, "Exact
# rays"): update them when the report changes.
QUALITY_PRESETS = {
    "DRAFT": (256, 64, "none", 0),
    "BALANCED": (256, 256, "none", -1),  # = RsmConfig's defaults
    "HIGH": (256, 256, "voxel", 8),
}
QUALITY_LABELS = {
    "DRAFT": ("Draft", "64 VPLs, no visibility: Cornell rel_rmse_8 0.19, noisier, about a third of Balanced's time"),
    "BALANCED": ("Balanced", "256 VPLs, no visibility (the defaults): Cornell rel_rmse_8 0.19; the sky's shadows "
                 "from exact rays in renders and bakes where the sky gives most of the light"),
    "HIGH": ("High", "256 VPLs, voxel visibility: Cornell rel_rmse_8 0.073, about 9x Balanced's time; the sky's "
             "shadows from exact rays: a window's sky light 0.028 from 0.073, its pass 19-200x dearer"),
}


def _apply_quality(self, _context):
    (self.rsm.resolution, self.rsm.vpl_samples, self.rsm.visibility,
     self.rsm.sky_rays) = QUALITY_PRESETS[self.quality]


def _enabled_changed(self, _context):
    # Start from a clean capture (edits made while disabled were not noted) and clear a past error.
    from .bridge import live

    live.reset()
    if self.enabled:
        live.request()


def _live_state():
    from .bridge import live  # imported late: the engine-only tools never load Blender's side

    return live


class BOUNCE_PG_settings(bpy.types.PropertyGroup):
    __annotations__ = {
        "enabled": BoolProperty(name="Enabled", description="Show Bounce's indirect light", default=False,
                                update=_enabled_changed),
        **{attr: PointerProperty(type=group) for attr, group in _GROUPS.items()},
        "view_mode": EnumProperty(
            name="View", description="Which light the viewport overlay adds",
            items=[("COMBINED", "Combined", "Direct and indirect light"),
                   ("INDIRECT", "Indirect", "Indirect light only"),
                   ("DIRECT", "Direct", "Direct light only"),
                   ("VOXELS", "Voxels", "Debug: the voxel grid of the rsm method's visibility on the "
                                        "surfaces (checkerboard by cell, magenta = hole)")],
            default="INDIRECT"),
        "exposure": FloatProperty(name="Exposure", description="Overlay brightness in stops (x 2^exposure)",
                                  default=0.0, min=-10.0, max=10.0),
        "strength": FloatProperty(name="Strength", description="Overlay brightness factor",
                                  default=1.0, min=0.0, max=10.0),
        "quality": EnumProperty(
            name="Quality", description="Sets RSM resolution and VPL samples",
            items=[(k, *QUALITY_LABELS[k]) for k in QUALITY_PRESETS], default="BALANCED",
            update=_apply_quality),
        "error_budget": FloatProperty(
            name="Error Budget", description="Choose for Budget picks the fastest setting expected within this "
            "relative error of a path tracer's indirect light (rel_rmse_8)", default=0.2, min=0.01, max=2.0,
            subtype="FACTOR"),
        # Written by Choose for Budget: the row it chose (the panel shows the note while the settings
        # still are that row) and its line ("rsm (...): ~8 % from a path tracer").
        "choice_row": StringProperty(name="Chosen Setting", default=""),
        "choice_note": StringProperty(name="Choice", default=""),
        # Read-only: written by the live overlay outside Blender data (a draw callback may not write).
        "last_update_ms": FloatProperty(name="Last Update (ms)", description="Time of the last overlay update",
                                        get=lambda _self: _live_state().STATE.last_update_ms, precision=1),
        "status": StringProperty(name="Status", description="What the overlay did last, or why it stopped",
                                 get=lambda _self: _live_state().status()),
        "world_averaged": BoolProperty(
            name="World Averaged", description="The world varies with direction but the overlay lights with its "
            "average colour: Capture World Light renders its map",
            get=lambda _self: _live_state().STATE.world_averaged),
    }


classes = (*_GROUPS.values(), BOUNCE_PG_settings)


def _from_blender(value):
    # Blender stores floats in 32 bits: 0.01 comes back as 0.0099999998; 7 significant digits is
    # what float32 holds, and restores the value the user typed.
    return float(f"{value:.7g}") if isinstance(value, float) else value


def to_config(settings) -> dict:
    """scene.bounce -> {group: config} (config.settings' form); raises ConfigError as the engine would."""
    return {attr: cls(**{name: _from_blender(getattr(getattr(settings, attr), name)) for name in config.limits(cls)})
            for attr, cls in CONFIGS.items()}


def set_from_config(settings, configs: dict) -> None:
    """{group: config} -> scene.bounce: every field of every group (the inverse of to_config)."""
    for attr, cfg in configs.items():
        group = getattr(settings, attr)
        for name, value in cfg.to_dict().items():
            setattr(group, name, value)


def register() -> None:
    for cls in classes:
        bpy.utils.register_class(cls)
    bpy.types.Scene.bounce = PointerProperty(type=BOUNCE_PG_settings)
    # Per light, saved with the light datablock: leave a lamp out of Bounce's light (Cycles keeps it).
    # One definition, shared with the CLI (which runs without the add-on registered).
    from .bridge.capture import define_light_switch

    define_light_switch()


def unregister() -> None:
    del bpy.types.Light.bounce_include
    del bpy.types.Scene.bounce
    for cls in reversed(classes):
        bpy.utils.unregister_class(cls)
