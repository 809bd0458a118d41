"""Every method's images at a set of settings on two procedural scenes, saved to an .npz: the record
that a change to the engine's structure changes no output (tests/blender/test_method_outputs.py).

    .venv/bin/python tools/method_outputs.py OUT.npz

tests/data/method_outputs.npz holds this tool's cases; the test renders them again and compares. A change that is
meant to change images regenerates the file with this command and says so in its commit.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

SCENES = ("cornell", "cornell-point")  # a spot (one RSM face) and a point light (six)
SIZE_PX = 48
RSM_TEXELS = 64
# name -> {group: {field: value}}: each method at its defaults and at the settings that take other paths.
CASES = {
    "direct": {"gi": {"method": "direct"}},
    "rsm": {"gi": {"method": "rsm"}, "rsm": {"vpl_samples": 32}},
    "rsm-vox": {"gi": {"method": "rsm"}, "rsm": {"vpl_samples": 32, "visibility": "voxel", "voxel_cells": 16}},
    "lpv": {"gi": {"method": "lpv"}, "lpv": {"grid_cells": 32}},
    "lpv-classes": {"gi": {"method": "lpv"}, "lpv": {"grid_cells": 16, "emitter_classes": True}},
    "lpv-b2": {"gi": {"method": "lpv", "bounces": 2}, "lpv": {"grid_cells": 16}},
    "lpv-casc": {"gi": {"method": "lpv"}, "lpv": {"grid_cells": 16, "cascades": 2}},
    "lpv-classic": {"gi": {"method": "lpv"}, "lpv": {"grid_cells": 16, "variant": "classic"}},
    "vct": {"gi": {"method": "vct"}, "vct": {"voxel_cells": 16, "diffuse_cones": 6}},
    "vct-b2": {"gi": {"method": "vct", "bounces": 2}, "vct": {"voxel_cells": 16, "diffuse_cones": 6}},
    "gather": {"gi": {"method": "gather"}, "probes": {"probes_per_side": 4}},
    "gather-b2": {"gi": {"method": "gather", "bounces": 2}, "probes": {"probes_per_side": 4}},
}


def settings_of(case: dict) -> dict:
    from addon.engine import config

    fields = {group: dict(case.get(group, {})) for group in config.GROUPS}
    fields["gi"]["resolution"] = SIZE_PX
    fields["gi"]["denoise"] = False  # the record predates the filter: the raw gathers
    fields["rsm"]["resolution"] = RSM_TEXELS
    return {group: cls(**fields[group]) for group, cls in config.GROUPS.items()}


def render_all(backend) -> dict[str, np.ndarray]:
    """{"<scene>/<case>/<product>": image} for every scene and case."""
    import bpy

    from addon.bridge import scenes
    from addon.bridge.capture import SceneCache
    from addon.engine import methods

    out = {}
    for scene_name in SCENES:
        scenes.build(scene_name)
        scene = SceneCache().update(bpy.context.evaluated_depsgraph_get(), SIZE_PX, SIZE_PX)
        for name, case in CASES.items():
            method = methods.create(backend, settings_of(case))
            method.set_scene(scene)
            for product, image in method.run().images.items():
                out[f"{scene_name}/{name}/{product}"] = image
    return out


def main(argv: list[str]) -> int:
    if len(argv) != 1 or argv[0].startswith("-") or not argv[0].endswith(".npz"):
        print("usage:", __doc__.strip().splitlines()[3].strip(), file=sys.stderr)
        return 2
    from addon.engine.backends.moderngl_backend import ModernGLBackend

    np.savez_compressed(argv[0], **render_all(ModernGLBackend()))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
