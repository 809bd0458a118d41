"""Install the extension zip as a user does, enable/disable it twice, check what it imports, and save
the user preferences (extension enabled, no splash) for the other scripts.  -- ZIP RESULT.json"""

import os
import sys

sys.path.insert(0, os.path.dirname(__file__))
import _common  # noqa: E402
import addon_utils  # noqa: E402
import bpy  # noqa: E402


def handler_counts():
    h = bpy.app.handlers
    return {n: len(getattr(h, n)) for n in dir(h) if isinstance(getattr(h, n), list)}


def enabled():
    return bool(addon_utils.check(_common.PACKAGE)[1]) and _common.PACKAGE in bpy.context.preferences.addons


def run(result):
    zip_path = _common.args()[0]
    before = handler_counts()
    result["install"] = sorted(bpy.ops.extensions.package_install_files(
        filepath=zip_path, repo="user_default", enable_on_install=True))
    result["enabled_after_install"] = enabled()
    result["scene_settings"] = hasattr(bpy.types.Scene, "bounce")
    result["default_method"] = bpy.context.scene.bounce.gi.method
    cycles = []
    for _ in range(2):
        bpy.ops.preferences.addon_disable(module=_common.PACKAGE)
        cycles.append({"enabled": enabled(), "scene_settings": hasattr(bpy.types.Scene, "bounce"),
                       "handlers_restored": handler_counts() == before})
        bpy.ops.preferences.addon_enable(module=_common.PACKAGE)
        cycles.append({"enabled": enabled(), "scene_settings": hasattr(bpy.types.Scene, "bounce")})
    result["cycles"] = cycles
    try:
        import OpenImageIO  # noqa: F401
        result["blender_has_openimageio"] = True
    except ImportError:
        result["blender_has_openimageio"] = False
    # Import every module of the extension that the UI can reach: none may need OpenImageIO.
    for name in ("addon.bridge.viewport", "addon.bridge.bake", "addon.bridge.live", "operators.bake"):
        _common.bounce(name)
    result["openimageio_imported"] = "OpenImageIO" in sys.modules
    bpy.context.preferences.view.show_splash = False
    bpy.ops.wm.save_userpref()


_common.main(run, _common.args()[1])
