"""BOUNCE_OT_bake in background mode (moderngl backend): images and vertex colours."""

import numpy as np
import pytest

pytestmark = pytest.mark.blender
bpy = pytest.importorskip("bpy")


@pytest.fixture
def cornell(bounce, fresh_blend):
    from addon.bridge import scenes

    bounce.register()
    scenes.build("cornell")
    s = bpy.context.scene.bounce
    s.gi.method, s.rsm.resolution, s.rsm.vpl_samples = "rsm", 32, 4
    yield bpy.context
    bounce.unregister()


def select(ctx, *names):
    for o in ctx.scene.objects:
        o.select_set(o.name in names)
    ctx.view_layer.objects.active = ctx.scene.objects[names[0]]


def test_bake_images_of_selected_objects(cornell):
    select(cornell, "Floor", "BackWall")
    assert bpy.ops.bounce.bake(size=16, pass_name="indirect", target="image") == {"FINISHED"}
    for name in ("Floor", "BackWall"):
        img = bpy.data.images[f"{name}_bounce_indirect"]
        assert tuple(img.size) == (16, 16) and img.is_float and img.packed_file is not None
        px = np.empty(16 * 16 * 4, np.float32)
        img.pixels.foreach_get(px)
        assert px.reshape(-1, 4)[:, 3].min() == 1.0 and px.reshape(-1, 4)[:, :3].mean() > 0


def test_bake_uses_the_scenes_lpv_settings(cornell):
    # The operator builds the method from the scene's settings, LPV's included (it once took only the
    # GI and RSM groups): the lit Floor baked with emitter classes reads the walls' light its own
    # upward light cancels without them (docs/LPV.md, "Emitter classes"), so the two bakes differ.
    s = cornell.scene.bounce
    s.gi.method, s.lpv.grid_cells = "lpv", 16
    select(cornell, "Floor")
    means = []
    for classes in (False, True):
        s.lpv.emitter_classes = classes
        assert bpy.ops.bounce.bake(size=16, pass_name="indirect", target="image") == {"FINISHED"}
        px = np.empty(16 * 16 * 4, np.float32)
        bpy.data.images["Floor_bounce_indirect"].pixels.foreach_get(px)
        means.append(px.reshape(-1, 4)[:, :3].mean())
    assert means[1] > 1.2 * means[0] > 0


def test_bake_vertex_colors(cornell):
    select(cornell, "Floor")
    # The Floor's corners lie outside the spot's cone: direct is 0 there, the bounce is not.
    assert bpy.ops.bounce.bake(pass_name="combined", target="vertex-colors") == {"FINISHED"}
    me = bpy.data.objects["Floor"].data
    attr = me.color_attributes["bounce_combined"]
    col = np.empty(len(me.loops) * 4, np.float32)
    attr.data.foreach_get("color", col)
    assert attr.domain == "CORNER" and col.reshape(-1, 4)[:, :3].max() > 0


def test_bake_cancels_with_a_message(cornell):
    bpy.context.scene.bounce.gi.method = "direct"
    select(cornell, "Floor")
    with pytest.raises(RuntimeError, match="needs an indirect method"):  # an ERROR report raises in bpy.ops
        bpy.ops.bounce.bake(pass_name="indirect")


def test_modal_bake_steps_per_timer_and_cancels_on_escape(bounce):
    # The windowed path cannot run headless (no window, no events), so its control flow is driven by
    # hand: a stand-in operator with the class's own modal/_finish and a recording _bake/_stop.
    import types

    from bounce.operators.bake import BOUNCE_OT_bake

    def stand_in(n):
        op = types.SimpleNamespace(_objects=[f"obj{i}" for i in range(n)], _next=0, _done=0, _failed=[],
                                   pass_name="indirect", target="image", reports=[], baked=[], stopped=0)
        op.report = lambda kind, msg: op.reports.append((next(iter(kind)), msg))

        def bake_one(obj):
            op.baked.append(obj)
            op._done += 1

        op._bake = bake_one
        op._stop = lambda _ctx: setattr(op, "stopped", op.stopped + 1)
        op._finish = lambda: BOUNCE_OT_bake._finish(op)
        return op

    context = types.SimpleNamespace(window_manager=types.SimpleNamespace(progress_update=lambda _v: None))
    timer, esc, mouse = (types.SimpleNamespace(type=t) for t in ("TIMER", "ESC", "MOUSEMOVE"))

    op = stand_in(3)
    assert BOUNCE_OT_bake.modal(op, context, mouse) == {"PASS_THROUGH"}  # the UI stays usable
    assert BOUNCE_OT_bake.modal(op, context, timer) == {"RUNNING_MODAL"}
    assert op.baked == ["obj0"]
    assert BOUNCE_OT_bake.modal(op, context, esc) == {"CANCELLED"}
    assert op.baked == ["obj0"] and op.stopped == 1  # the rest never started; timer and progress ended
    assert op.reports[-1] == ("WARNING", "bake cancelled after 1 of 3 object(s)")

    op = stand_in(2)
    assert BOUNCE_OT_bake.modal(op, context, timer) == {"RUNNING_MODAL"}
    assert BOUNCE_OT_bake.modal(op, context, timer) == {"FINISHED"}
    assert op.baked == ["obj0", "obj1"] and op.stopped == 1


def test_bake_is_kept_by_the_file(cornell, tmp_path):
    # A new image has no users; Blender drops such datablocks when it saves. The bake's fake user keeps
    # it (the real-Blender tier saves and reloads in 4.3; this is the same under 5.0).
    select(cornell, "Floor")
    assert bpy.ops.bounce.bake(size=8, pass_name="indirect", target="image") == {"FINISHED"}
    assert bpy.data.images["Floor_bounce_indirect"].use_fake_user
    path = tmp_path / "kept.blend"
    bpy.ops.wm.save_as_mainfile(filepath=str(path))
    bpy.ops.wm.open_mainfile(filepath=str(path))
    img = bpy.data.images["Floor_bounce_indirect"]
    assert img.packed_file is not None and tuple(img.size) == (8, 8)


def test_unlit_scene_bakes_with_a_warning(cornell, capfd):
    # Black images reported as a success would look like a broken bake: the operator says why.
    bpy.data.objects.remove(bpy.data.objects["Spot"])
    select(cornell, "Floor")
    capfd.readouterr()
    assert bpy.ops.bounce.bake(size=8, pass_name="indirect", target="image") == {"FINISHED"}
    out = capfd.readouterr().out
    assert "no light sources" in out, out  # background Blender prints reports as "Warning: <message>"
