"""House rules as tests: addon/engine stays Blender-free and imports without Blender."""

import ast
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
FORBIDDEN = {"bpy", "gpu", "mathutils", "bmesh", "gpu_extras", "bl_math"}


def _imported_roots(path: Path):
    tree = ast.parse(path.read_text(), filename=str(path))
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            for alias in node.names:
                yield node.lineno, alias.name.split(".")[0]
        elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
            yield node.lineno, node.module.split(".")[0]


def test_engine_never_imports_blender():
    offenders = [
        f"{p.relative_to(ROOT)}:{line} imports {mod}"
        for p in sorted((ROOT / "addon" / "engine").rglob("*.py"))
        for line, mod in _imported_roots(p)
        if mod in FORBIDDEN
    ]
    assert offenders == []


def test_rule_detects_a_violation(tmp_path):
    # The checker itself must be able to fail.
    bad = tmp_path / "bad.py"
    bad.write_text("import os\nfrom bpy import types\n")
    assert [m for _, m in _imported_roots(bad) if m in FORBIDDEN] == ["bpy"]


def test_engine_imports_without_blender():
    code = (
        "import sys; import addon.engine, addon.engine.sh, addon.engine.config, addon.engine.shader_source;"
        "import addon.engine.backends.moderngl_backend;"
        "bad = sorted(m for m in sys.modules if m.split('.')[0] in {'bpy', 'gpu', 'mathutils', 'bmesh'});"
        "assert not bad, bad"
    )
    subprocess.run([sys.executable, "-c", code], cwd=ROOT, check=True)
