"""Shared fixtures. The repository root is put on sys.path so `import addon` works in every tier.

Fixtures create one GPU context per session (as moderngl's own test suite does) and check for GL
errors around each GPU test.
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

# The real-Blender tier needs root and a 1.8 GB chroot: `make test-blender` runs it (it sets this).
if not os.environ.get("BOUNCE_REAL_BLENDER"):
    collect_ignore = ["real_blender"]


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


@pytest.fixture(scope="session")
def bounce(tmp_path_factory):
    """The repository imported as the package `bounce` (a symlink), as Blender imports the extension,
    so the relative imports between addon/, operators/ and panels/ resolve."""
    import importlib

    pytest.importorskip("bpy")
    link_dir = tmp_path_factory.mktemp("pkg")
    (link_dir / "bounce").symlink_to(ROOT, target_is_directory=True)
    sys.path.insert(0, str(link_dir))
    try:
        yield importlib.import_module("bounce")
    finally:
        sys.path.remove(str(link_dir))


@pytest.fixture
def fresh_blend():
    """An empty Blender file (factory settings), so bpy tests do not see each other's data."""
    bpy = pytest.importorskip("bpy")
    bpy.ops.wm.read_factory_settings(use_empty=True)
    yield bpy
    bpy.ops.wm.read_factory_settings(use_empty=True)
