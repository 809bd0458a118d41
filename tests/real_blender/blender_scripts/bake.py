"""The Bake operator with the scene's settings, overlay off, for each method; save the file.
-- OUT.blend RESULT.json   (run with the scene .blend opened)

Each method (and diffusion with its cone fields) bakes the Floor and BackWall into packed images at
32 x 32 texels (indirect light; `direct` bakes its direct light) and the Floor into vertex colours; the
last method's images stay in the file."""

import os
import sys

sys.path.insert(0, os.path.dirname(__file__))
import _common  # noqa: E402
import bpy  # noqa: E402
import numpy as np  # noqa: E402

OBJECTS = ("Floor", "BackWall")


def select(names):
    for obj in bpy.context.scene.objects:
        obj.select_set(obj.name in names)
    bpy.context.view_layer.objects.active = bpy.data.objects[names[0]]


def run(result):
    out, _ = _common.args()[:2]
    settings = bpy.context.scene.bounce
    result["overlay_enabled"] = settings.enabled
    result["default_method"] = settings.gi.method
    # Small grids: the test checks that each method bakes in this Blender, not its accuracy.
    settings.lpv.grid_cells, settings.vct.voxel_cells, settings.vct.diffuse_cones = 16, 16, 6
    bake = _common.bounce("addon.bridge.bake")
    methods = {}
    # Diffusion's single field with emitter classes first (the transfer's and the classes' programs in
    # place of the default cone fields'), so the last bake is the registry's last method's, whose images
    # stay in the file.
    runs = [("diffusion-single-field", "diffusion", False)]
    runs += [(method, method, True) for method in _common.bounce("addon.engine.registry").NAMES]
    for key, method, cone_fields in runs:
        settings.gi.method = method
        settings.diffusion.cone_fields = cone_fields
        settings.diffusion.emitter_class_passes = not cone_fields
        pass_name = "direct" if method == "direct" else "indirect"
        select(OBJECTS)
        status = bpy.ops.bounce.bake(size=32, pass_name=pass_name, target="image")
        images = {o: _common.image_stats(bpy.data.images[bake.image_name(o, pass_name)]) for o in OBJECTS}
        select(("Floor",))
        vc_status = bpy.ops.bounce.bake(pass_name=pass_name, target="vertex-colors")
        attr = bpy.data.objects["Floor"].data.color_attributes[bake.attribute_name(pass_name)]
        colors = np.empty(len(attr.data) * 4, np.float32)
        attr.data.foreach_get("color", colors)
        methods[key] = {"status": sorted(status), "images": images, "vertex_colors_status": sorted(vc_status),
                        "vertex_colors_max": float(colors.reshape(-1, 4)[:, :3].max())}
    result["methods"] = methods
    result["openimageio_imported"] = "OpenImageIO" in sys.modules
    bpy.ops.wm.save_as_mainfile(filepath=out)


_common.main(run, _common.args()[1])
