"""The #include resolver and the mapping of compiler messages back to gpu_shaders/<file>:<line>."""

import pytest

from addon.engine.errors import ShaderCompileError
from addon.engine.shader_source import LINE_STRIDE, load, map_compile_error


@pytest.fixture
def root(tmp_path):
    (tmp_path / "common").mkdir()
    (tmp_path / "common" / "a.glsl").write_text("float a() { return 1.0; }\n")
    (tmp_path / "common" / "b.glsl").write_text('#include "common/a.glsl"\nfloat b() { return a(); }\n')
    (tmp_path / "main.glsl").write_text(
        '#include "common/a.glsl"\n#include "common/b.glsl"\nvoid main() {\n    oops;\n}\n'
    )
    return tmp_path


def test_include_once_and_line_directives(root):
    src = load("main.glsl", root)
    assert src.files == ("<generated>", "main.glsl", "common/a.glsl", "common/b.glsl")
    assert src.text.count("float a()") == 1  # a.glsl pulled in twice, emitted once
    lines = src.text.splitlines()
    # main.glsl line 4 ("oops;") must be announced as line 4 of file 1 by the nearest #line above it.
    idx = lines.index("    oops;")
    directive = next(line for line in reversed(lines[:idx]) if line.startswith("#line"))
    encoded = int(directive.split()[1]) + (idx - lines.index(directive) - 1)
    assert divmod(encoded, LINE_STRIDE) == (1, 4)


@pytest.mark.parametrize(
    "log",
    ["0:100004(5): error: `oops' undeclared", "0(100004) : error C1008: undefined variable", "ERROR: 0:100004: 'oops'",
     "  | :100004:13: Error: `oops' undeclared"],
)
def test_error_locations_are_mapped(root, log):
    src = load("main.glsl", root)
    assert "gpu_shaders/main.glsl:4" in src.map_error(log)


def test_unknown_index_left_alone():
    # Lines of the generated header (index 0) and out-of-range indices keep their raw location.
    assert map_compile_error("0:3(1): error", ("<generated>", "x.glsl")) == "0:3(1): error"
    assert map_compile_error("0:900003(1): error", ("<generated>", "x.glsl")) == "0:900003(1): error"


def test_cycle_is_refused(tmp_path):
    (tmp_path / "x.glsl").write_text('#include "y.glsl"\n')
    (tmp_path / "y.glsl").write_text('#include "x.glsl"\n')
    with pytest.raises(ShaderCompileError, match="include cycle: x.glsl -> y.glsl -> x.glsl"):
        load("x.glsl", tmp_path)


def test_missing_include_names_includer(tmp_path):
    (tmp_path / "x.glsl").write_text('#include "nope.glsl"\n')
    with pytest.raises(ShaderCompileError, match=r"gpu_shaders/nope.glsl \(included from gpu_shaders/x.glsl\)"):
        load("x.glsl", tmp_path)
