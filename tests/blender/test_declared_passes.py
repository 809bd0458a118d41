"""Declared passes (addon/engine/passes/declare.py): each method's pass lists are what runs, every input
a pass reads is written by a pass before it (or is the scene's own), and the products are allocated
from the declarations."""

import importlib.util
import re
from pathlib import Path

import pytest

from addon.engine import methods, registry
from addon.engine.passes import declare

pytestmark = [pytest.mark.blender, pytest.mark.gpu]
bpy = pytest.importorskip("bpy")

ROOT = Path(__file__).resolve().parents[2]
_spec = importlib.util.spec_from_file_location("method_outputs", ROOT / "tools" / "method_outputs.py")
method_outputs = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(method_outputs)

HALF_KEYS = {"total", "solve", "gather", "readback"}  # DirectMethod's own timings, not passes
CASCADE_KEY = re.compile(r"^(?P<pass>[a-z_]+)_cascade\d+$")  # a pass's time per LPV cascade


def _ordered(cls) -> list:
    return [decl for half in declare.HALVES for decl in cls.PASSES[half]]


@pytest.mark.parametrize("spec", registry.METHODS, ids=lambda s: s.name)
def test_every_input_is_written_before_it_is_read(spec):
    written = set()
    for decl in _ordered(methods.get(spec.name)):
        missing = [p.key for p in decl.inputs if p.group != "scene" and p.key not in written]
        assert missing == [], f"{spec.name}: {decl.name} reads {missing} before any pass writes them"
        written |= {p.key for p in decl.outputs}


@pytest.mark.parametrize("spec", registry.METHODS, ids=lambda s: s.name)
def test_products_are_declared_outputs_of_the_gather(spec):
    gathered = {p.name for decl in methods.get(spec.name).PASSES["gather"] for p in decl.outputs}
    assert set(spec.products) - {"albedo"} <= gathered


@pytest.fixture(scope="module")
def point_scene():
    from addon.bridge import scenes
    from addon.bridge.capture import SceneCache

    scenes.build("cornell-point")  # six RSM faces: every per-face loop runs more than once
    return SceneCache().update(bpy.context.evaluated_depsgraph_get(), 32, 32)


CASES = method_outputs.CASES


@pytest.mark.parametrize("case", CASES)
def test_the_declared_lists_are_what_runs(gl, point_scene, case):
    method = methods.create(gl, method_outputs.settings_of(CASES[case]))
    method.set_scene(point_scene)
    timings = method.run().timings_ms
    declared = {decl.name for decl in _ordered(type(method))}
    for key in set(timings) - HALF_KEYS:
        m = CASCADE_KEY.match(key)
        assert (m.group("pass") if m else key) in declared, f"{case}: {key} ran but is not declared"
    # Each product texture is the declared format at the image's size.
    ports = {p.name: p for decl in type(method).PASSES["gather"] for p in decl.outputs}
    for name, texture in method.product_textures().items():
        assert texture.format == ports[name].format and texture.size == (32, 32), name
