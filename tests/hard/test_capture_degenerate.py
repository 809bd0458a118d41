"""Hard case 6 (capture side): NaN/Inf and zero-area triangles from Blender are dropped with one warning,
and the captured scene renders finite. Needs bpy."""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("bpy")

pytestmark = [pytest.mark.blender, pytest.mark.gpu]


def test_nan_inf_and_zero_area_dropped_with_one_warning(fresh_blend, gl, figures):
    from hard_scenes import assert_sane, camera, render, sanity

    from addon.bridge.capture import capture

    bpy = fresh_blend
    nan, inf = float("nan"), float("inf")
    verts = [(-2, -2, 0), (2, -2, 0), (2, 2, 0), (-2, 2, 0),   # a good quad (2 triangles)
             (0, 0, 1), (1, 0, 1), (2, 0, 1),                  # collinear: zero area
             (0, 0, 2), (0, 0, 2), (1, 1, 2),                  # duplicated vertex: zero area
             (0, 0, 3), (1, 0, 3), (nan, 1, 3),                # NaN corner
             (0, 0, 4), (1, 0, 4), (inf, 1, 4)]                # Inf corner
    me = bpy.data.meshes.new("Bad")
    me.from_pydata(verts, [], [(0, 1, 2, 3), (4, 5, 6), (7, 8, 9), (10, 11, 12), (13, 14, 15)])
    bpy.context.scene.collection.objects.link(bpy.data.objects.new("Bad", me))
    lamp = bpy.data.objects.new("L", bpy.data.lights.new("L", "POINT"))
    lamp.data.energy = 100.0
    lamp.location = (0, 0, 1.5)
    bpy.context.scene.collection.objects.link(lamp)
    bpy.context.view_layer.update()
    sc = capture(bpy.context.evaluated_depsgraph_get(), 32, 32)
    # Exact: the quad's 2 triangles kept, the 4 bad ones dropped, one warning naming 4.
    # Capture is method-independent: its figures go in a "capture" column.
    figures("Blender mesh with NaN/Inf/zero-area faces: triangles kept", "capture", sc.triangle_count, "= 2")
    figures("Blender mesh with NaN/Inf/zero-area faces: warnings", "capture", "; ".join(sc.warnings),
            "one, naming 4")
    assert sc.triangle_count == 2
    assert np.isfinite(sc.positions_m).all() and np.isfinite(sc.normals).all()
    assert [w for w in sc.warnings if w.startswith("4 triangles")] and len(sc.warnings) == 1
    sc.camera = camera([0, -3, 3], [0, 1, -1], 32)
    for name in ("direct", "rsm"):
        images = render(gl, name, sc)
        figures("Blender mesh with NaN/Inf/zero-area faces: rendered outputs", name, sanity(images), "finite, min ≥ 0")
        assert_sane(images)
        assert images["direct"].max() > 0
