"""No output changes: every method at tools/method_outputs.py's settings gives the images recorded in
tests/data/method_outputs.npz (the tool's record of them). The same passes on the same inputs in the
same order on the same rasteriser: equal bit for bit; 1e-6 relative is the allowance for a pass order
that changes float summation, and any change beyond it is an output change that must regenerate the
file (the tool's docstring says how)."""

import importlib.util
from pathlib import Path

import numpy as np
import pytest

pytestmark = [pytest.mark.blender, pytest.mark.gpu]
pytest.importorskip("bpy")

ROOT = Path(__file__).resolve().parents[2]
_spec = importlib.util.spec_from_file_location("method_outputs", ROOT / "tools" / "method_outputs.py")
method_outputs = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(method_outputs)


def test_every_method_gives_the_recorded_images(gl, fresh_blend):
    recorded = np.load(ROOT / "tests" / "data" / "method_outputs.npz")
    images = method_outputs.render_all(gl)
    assert sorted(images) == sorted(recorded.files)
    for key in recorded.files:
        want = recorded[key]
        assert want[..., :3].max() > 0 or key.endswith("/glossy"), key  # light, not an empty record
        np.testing.assert_allclose(images[key], want, rtol=1e-6, atol=1e-6 * float(np.abs(want).max()), err_msg=key)
