"""Loads GLSL bodies from gpu_shaders/, resolves `#include "path"`, maps compile errors to file:line.

Each included file is wrapped in `#line` directives whose line number carries the file too:
`#line <file-index * LINE_STRIDE + n>`. Compilers differ in whether they print the source-string number
of `#line` (Mesa always prints 0), but all print the line, so the file is decoded from the line alone;
`map_compile_error` rewrites such locations to `gpu_shaders/<file>:<line>`. This works for every
backend, including Blender's, which prepends its own declarations.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

from .errors import ShaderCompileError

SHADER_ROOT = Path(__file__).resolve().parents[2] / "gpu_shaders"

LINE_STRIDE = 100_000  # no shader file comes near this many lines
_INCLUDE = re.compile(r'^\s*#\s*include\s+"([^"]+)"\s*$')
# Mesa: "0:12(3): error: ..."; NVIDIA: "0(12) : error ..."; AMD/Intel: "ERROR: 0:12: ...";
# Blender's own log: ":12:3: Error: ...". Group "line" is the (encoded) line number.
_LOCATIONS = (
    re.compile(r"\b\d+:(?P<line>\d+)\(\d+\)"),
    re.compile(r"\b\d+\((?P<line>\d+)\)"),
    re.compile(r"(?<![\w:]):(?P<line>\d+):\d+:"),
    re.compile(r"\b\d+:(?P<line>\d+)\b"),
)


@dataclass(frozen=True)
class ShaderSource:
    """An assembled GLSL body and the files its `#line` numbers refer to (index 0 = generated header)."""

    text: str
    files: tuple[str, ...]

    def map_error(self, log: str) -> str:
        return map_compile_error(log, self.files)


def load(relpath: str, root: Path | None = None) -> ShaderSource:
    """Read gpu_shaders/<relpath> with its includes resolved (each file included once, cycles refused)."""
    return load_stages(relpath, root=root)[0]


def load_stages(*relpaths: str, root: Path | None = None) -> list[ShaderSource]:
    """Load the stages of one program (vertex, fragment) with one shared file table, so a location in
    any stage's compiler log maps to the right file. Every returned source carries the whole table."""
    root = SHADER_ROOT if root is None else root
    files: list[str] = ["<generated>"]
    texts = []
    for relpath in relpaths:
        out: list[str] = []
        _expand(relpath, root, files, out, stack=(), done=set())
        texts.append("\n".join(out) + "\n")
    return [ShaderSource(text, tuple(files)) for text in texts]


def _expand(relpath: str, root: Path, files: list[str], out: list[str], stack: tuple[str, ...], done: set[str]):
    if relpath in stack:
        chain = " -> ".join((*stack, relpath))
        raise ShaderCompileError(f"include cycle: {chain}")
    if relpath in done:
        return  # include-once: shared helpers may be pulled in by several files
    path = root / relpath
    if not path.is_file():
        where = f" (included from gpu_shaders/{stack[-1]})" if stack else ""
        raise ShaderCompileError(f"shader file not found: gpu_shaders/{relpath}{where}")
    done.add(relpath)
    index = len(files)
    files.append(relpath)
    out.append(f"#line {index * LINE_STRIDE + 1}")
    for lineno, line in enumerate(path.read_text().splitlines(), start=1):
        m = _INCLUDE.match(line)
        if m:
            _expand(m.group(1), root, files, out, (*stack, relpath), done)
            out.append(f"#line {index * LINE_STRIDE + lineno + 1}")
        else:
            out.append(line)


def map_compile_error(log: str, files: tuple[str, ...]) -> str:
    """Rewrite compiler locations whose line encodes a file (see module doc) to `gpu_shaders/<file>:<line>`."""
    mapped = []
    for line in log.splitlines():
        for pattern in _LOCATIONS:
            m = pattern.search(line)
            if m:
                index, lineno = divmod(int(m.group("line")), LINE_STRIDE)
                if 0 < index < len(files):
                    line = line[: m.start()] + f"gpu_shaders/{files[index]}:{lineno}" + line[m.end() :]
                break
        mapped.append(line)
    return "\n".join(mapped)
