"""The same passes on Blender's gpu module and on moderngl give the same numbers (both fp32)."""

import numpy as np
import pytest

from addon.engine import selftest, sh, shader_source
from addon.engine.backends.base import ShaderSpec
from addon.engine.errors import ShaderCompileError

pytestmark = [pytest.mark.blender, pytest.mark.gpu]


def test_compute_pass_agrees(gl, blender_backend):
    src = np.random.default_rng(3).random((4, 3, 5, 4)).astype(np.float32)
    a = selftest.run_scale_offset(gl, src, -1.5)
    b = selftest.run_scale_offset(blender_backend, src, -1.5)
    np.testing.assert_allclose(b, a, atol=1e-6)  # identical fp32 arithmetic; a few ulp at most


def test_additive_splat_agrees(gl, blender_backend):
    rng = np.random.default_rng(4)
    voxels = rng.integers(0, [7, 6, 5], size=(200, 3))
    values = rng.random((200, 4)).astype(np.float32)
    a = selftest.run_splat(gl, (7, 6, 5), voxels, values)
    b = selftest.run_splat(blender_backend, (7, 6, 5), voxels, values)
    expected = np.zeros((5, 6, 7, 4))
    np.add.at(expected, (voxels[:, 2], voxels[:, 1], voxels[:, 0]), values)
    # Blending order may differ between drivers: fp32 sums of <= ~15 values in [0, 1) agree to ~1e-6.
    np.testing.assert_allclose(a, expected, atol=1e-5)
    np.testing.assert_allclose(b, expected, atol=1e-5)


def test_sh_glsl_agrees(blender_backend):
    rng = np.random.default_rng(5)
    dirs = rng.normal(size=(32, 3))
    dirs /= np.linalg.norm(dirs, axis=1, keepdims=True)
    coeffs = rng.normal(size=(32, 4))
    out = selftest.run_sh_eval(blender_backend, dirs, coeffs)
    np.testing.assert_allclose(out["lobe_out"], sh.cosine_lobe_l1(dirs), atol=1e-6)
    np.testing.assert_allclose(out["scalar_out"][:, 0], sh.irradiance(coeffs, dirs), atol=1e-5)


def test_blender_compile_error_names_file_and_line(blender_backend, tmp_path, monkeypatch):
    (tmp_path / "broken.comp.glsl").write_text("void main() {\n    float x = nope;\n}\n")
    monkeypatch.setattr(shader_source, "SHADER_ROOT", tmp_path)
    with pytest.raises(ShaderCompileError, match=r"gpu_shaders/broken\.comp\.glsl:2"):
        blender_backend.program(ShaderSpec(name="broken", compute="broken.comp.glsl", local_size=(1, 1, 1)))


def test_a_new_moderngl_backend_leaves_blenders_context_current(blender_backend):
    # Creating a moderngl context makes it current; the backend must hand the caller's back (a bake
    # in background mode makes one, and Blender's next texture failed: "gpu.texture.new(...) failed").
    from addon.engine.backends.moderngl_backend import ModernGLBackend

    ModernGLBackend()
    tex = blender_backend.texture((4, 4), data=np.ones((4, 4, 4), np.float32))
    np.testing.assert_array_equal(blender_backend.read(tex), 1.0)
