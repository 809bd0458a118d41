"""Build a procedural scene with the installed extension and save it (a .blend of this Blender's
version: files saved by 5.x do not open in 4.x).  -- NAME OUT.blend RESULT.json"""

import os
import sys

sys.path.insert(0, os.path.dirname(__file__))
import _common  # noqa: E402


def run(result):
    name, out = _common.args()[:2]
    _common.bounce("addon.bridge.scenes").save(name, out)
    result["saved"] = out


_common.main(run, _common.args()[2])
