"""ModernGLBackend against exact answers: compute pass, additive splats, SH in GLSL, compile errors."""

import numpy as np
import pytest

from addon.engine import selftest, sh, shader_source
from addon.engine.backends.base import ShaderSpec
from addon.engine.errors import ShaderCompileError

pytestmark = pytest.mark.gpu


def expected_scale_offset(src, scale):
    d, h, w, _ = src.shape
    z, y, x = np.meshgrid(np.arange(d), np.arange(h), np.arange(w), indexing="ij")
    out = src.astype(np.float64) * scale
    out[..., 0] += x
    out[..., 1] += y
    out[..., 2] += z
    out[..., 3] += sh.Y00 * np.pi  # sh_irradiance((1,0,0,0), +z) = c0 * A0 * Y00 = 0.886227
    return out


def test_compute_pass_exact(gl):
    src = np.random.default_rng(1).random((3, 5, 6, 4)).astype(np.float32)
    out = selftest.run_scale_offset(gl, src, 2.5)
    # fp32 arithmetic on values < 10: a few ulp.
    np.testing.assert_allclose(out, expected_scale_offset(src, 2.5), atol=2e-6)


def test_additive_splat_sums_points_in_one_voxel(gl):
    voxels = np.array([[1, 2, 0], [1, 2, 0], [5, 4, 2], [0, 0, 1]])
    values = np.array([[1, 2, 3, 4], [0.5, 0.25, 0.125, 1], [7, 8, 9, 10], [-1, 0, 1, 0]], np.float32)
    vol = selftest.run_splat(gl, (6, 5, 3), voxels, values)
    expected = np.zeros((3, 5, 6, 4), np.float32)
    for (x, y, z), v in zip(voxels, values, strict=True):
        expected[z, y, x] += v
    np.testing.assert_array_equal(vol, expected)  # sums of dyadic fractions are exact in fp32


def test_sh_glsl_matches_numpy(gl):
    rng = np.random.default_rng(2)
    dirs = rng.normal(size=(64, 3))
    dirs /= np.linalg.norm(dirs, axis=1, keepdims=True)
    coeffs = rng.normal(size=(64, 4))
    out = selftest.run_sh_eval(gl, dirs, coeffs)
    np.testing.assert_allclose(out["basis_out"], sh.basis_l1(dirs), atol=1e-6)
    np.testing.assert_allclose(out["lobe_out"], sh.cosine_lobe_l1(dirs), atol=1e-6)
    np.testing.assert_allclose(out["scalar_out"][:, 0], sh.irradiance(coeffs, dirs), atol=1e-5)
    np.testing.assert_allclose(out["scalar_out"][:, 1], sh.evaluate(coeffs, dirs), atol=1e-5)


def test_compile_error_names_file_and_line(gl, tmp_path, monkeypatch):
    (tmp_path / "common").mkdir()
    (tmp_path / "common" / "ok.glsl").write_text("float ok() { return 1.0; }\n")
    (tmp_path / "broken.comp.glsl").write_text('#include "common/ok.glsl"\nvoid main() {\n    float x = nope;\n}\n')
    monkeypatch.setattr(shader_source, "SHADER_ROOT", tmp_path)
    with pytest.raises(ShaderCompileError, match=r"gpu_shaders/broken\.comp\.glsl:3"):
        gl.program(ShaderSpec(name="broken", compute="broken.comp.glsl", local_size=(1, 1, 1)))


def test_programs_are_cached(gl):
    assert gl.program(selftest.SCALE_OFFSET) is gl.program(selftest.SCALE_OFFSET)


def test_dropped_gl_objects_are_released(gl):
    """Textures and meshes whose handles are dropped are released at the next allocation, inside the
    backend's own context: moderngl queues them (gc_mode "context_gc") and the queue is empty again
    after one more texture. Without it every new scene or re-voxelization leaked its GPU memory."""
    import gc

    from addon.engine.passes import gbuffer

    prog = gl.program(gbuffer.SPEC)
    attrs = {v.name: np.zeros((3, int(v.type[-1])), np.float32) for v in gbuffer.SPEC.attributes}  # vecN
    for _ in range(10):
        gl.mesh(prog, attrs, "triangles")
        gl.texture((4, 4))
    gc.collect()
    assert len(gl.ctx._objects) > 0  # queued, not yet released
    kept = gl.texture((4, 4))
    assert len(gl.ctx._objects) == 0
    assert kept.gl.glo > 0
