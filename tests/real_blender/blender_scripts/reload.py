"""Open a file saved after a bake and report its Bounce images.  -- RESULT.json (run with the .blend)"""

import os
import sys

sys.path.insert(0, os.path.dirname(__file__))
import _common  # noqa: E402
import bpy  # noqa: E402


def run(result):
    result["images"] = {img.name: _common.image_stats(img) for img in bpy.data.images if "_bounce_" in img.name}
    result["method"] = bpy.context.scene.bounce.gi.method
    result["lpv_grid_cells"] = bpy.context.scene.bounce.lpv.grid_cells


_common.main(run, _common.args()[0])
