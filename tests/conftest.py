"""Shared fixtures. The repository root is put on sys.path so `import addon` works in every tier.

Fixtures create one GPU context per session (as moderngl's own test suite does) and check for GL
errors around each GPU test.
"""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))


@pytest.fixture(scope="session")
def gl_backend():
    """ModernGLBackend on EGL (llvmpipe without a GPU); skips cleanly where no 4.3 context exists."""
    from addon.engine.backends.moderngl_backend import ModernGLBackend
    from addon.engine.errors import BackendUnavailable

    try:
        return ModernGLBackend()
    except BackendUnavailable as exc:
        pytest.skip(f"no OpenGL 4.3 context: {exc}")


@pytest.fixture
def gl(gl_backend):
    """The session backend, asserting that the test left no GL error behind (in its own context)."""
    assert gl_backend.gl_error() == "GL_NO_ERROR"
    yield gl_backend
    assert gl_backend.gl_error() == "GL_NO_ERROR"


@pytest.fixture(scope="session")
def blender_backend():
    """BlenderGPUBackend in background mode (initialises Blender's GPU once per session)."""
    pytest.importorskip("bpy")
    from addon.bridge.blender_gpu_backend import BlenderGPUBackend

    return BlenderGPUBackend()


@pytest.fixture
def fresh_blend():
    """An empty Blender file (factory settings), so bpy tests do not see each other's data."""
    bpy = pytest.importorskip("bpy")
    bpy.ops.wm.read_factory_settings(use_empty=True)
    yield bpy
    bpy.ops.wm.read_factory_settings(use_empty=True)
