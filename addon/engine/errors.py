"""The one error hierarchy of Bounce. The CLI turns any BounceError into one line and exit status 2."""


class BounceError(Exception):
    """Base of every error Bounce raises on purpose (bad input, missing capability)."""


class ConfigError(BounceError, ValueError):
    """A configuration value is unknown or out of its allowed range."""


class SceneError(BounceError):
    """The scene cannot be used as asked (no camera, unreadable file, ...)."""


class ShaderCompileError(BounceError):
    """A GLSL program failed to compile or link; the message names gpu_shaders/<file>:<line>."""


class BackendUnavailable(BounceError):
    """A GPU backend cannot be created in this process (no EGL, no Blender GPU, ...)."""
