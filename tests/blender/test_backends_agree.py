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


@pytest.mark.parametrize("cone", [1, 4])
def test_cone_field_passes_agree(gl, blender_backend, cone):
    # The cone fields' emitters and step (diffusion/emit.comp.glsl, propagate.comp.glsl with CONES),
    # whose matrices come in as long #defines of GLSL constructors: the same numbers on both backends.
    from addon.engine.grid import Grid
    from addon.engine.passes import diffusion_cells, diffusion_inject, diffusion_propagate

    grid = Grid(np.zeros(3), 0.5, (5, 4, 3))
    rng = np.random.default_rng(7)
    shape = (3, 4, 5)
    occupied = rng.random(shape) < 0.4
    normal = rng.normal(size=(*shape, 3))
    normal /= np.linalg.norm(normal, axis=-1, keepdims=True)
    voxels = {"vox_albedo": np.where(occupied[..., None], 0.6, 0.0) * np.ones(4),
              "vox_normal": np.concatenate([normal * occupied[..., None], np.ones((*shape, 1))], -1),
              "vox_projected": np.where(occupied[..., None], rng.uniform(0.2, 1.2, (*shape, 4)), 0.0)}
    flux = {k: rng.uniform(0.0, 2.0, (*shape, 4)).astype(np.float32) for k in ("flux_plus", "flux_minus")}
    out = []
    for be in (gl, blender_backend):
        textures = {k: be.texture(grid.dims, "RGBA32F", v.astype(np.float32)) for k, v in voxels.items()}
        cells = diffusion_cells.textures(be, grid)
        diffusion_cells.run(be, textures, cells, grid)
        sets = [{f"sh_{c}": be.texture(grid.dims) for c in "rgb"} for _ in range(2)]
        diffusion_inject.emit(be, {k: be.texture(grid.dims, "RGBA32F", v) for k, v in flux.items()}, cells, sets[0],
                              grid, vox_albedo=textures["vox_albedo"], cone=cone)
        absorbed = diffusion_propagate.sides(be, grid)
        for i in range(3):  # light leaves its occupied cells, then meets others
            diffusion_propagate.run(be, sets[i % 2], sets[(i + 1) % 2], absorbed, cells, grid, first_step=i == 0,
                                    cone=cone)
        out.append([be.read(sets[i][f"sh_{c}"]) for i in range(2) for c in "rgb"]
                   + [be.read(absorbed[k]) for k in ("flux_plus", "flux_minus")])
    assert np.abs(out[0][3]).max() > 0 and np.abs(out[0][6] + out[0][7]).max() > 0  # moved, and absorbed
    for a, b in zip(*out, strict=True):
        # fp32 on both: the emitters' gram^-1 (condition number 319) amplifies rounding to 3e-5 relative
        # (tests/gpu/test_diffusion.py), and one step adds a few ulp.
        np.testing.assert_allclose(b, a, rtol=0, atol=1e-4 * np.abs(a).max())
