"""Loads GLSL bodies from gpu_shaders/, resolves `#include "path"`, maps compile errors to file:line.

Each included file is wrapped in `#line <n> <file-index>` directives, so any GLSL compiler reports
errors as `<file-index>:<line>`; `map_compile_error` rewrites those to `gpu_shaders/<file>:<line>`.
This works for every backend, including Blender's, which prepends its own declarations.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

from .errors import ShaderCompileError

SHADER_ROOT = Path(__file__).resolve().parents[2] / "gpu_shaders"

_INCLUDE = re.compile(r'^\s*#\s*include\s+"([^"]+)"\s*$')
# Mesa: "1:12(3): error: ..."; NVIDIA: "1(12) : error ..."; AMD/Intel: "ERROR: 1:12: ..."
_LOCATIONS = (
    re.compile(r"\b(\d+):(\d+)\((\d+)\)"),
    re.compile(r"\b(\d+)\((\d+)\)"),
    re.compile(r"\b(\d+):(\d+)\b"),
)


@dataclass(frozen=True)
class ShaderSource:
    """An assembled GLSL body and the files its `#line` indices refer to (index 0 = generated header)."""

    text: str
    files: tuple[str, ...]

    def map_error(self, log: str) -> str:
        return map_compile_error(log, self.files)


def load(relpath: str, root: Path = SHADER_ROOT) -> ShaderSource:
    """Read gpu_shaders/<relpath> with its includes resolved (each file included once, cycles refused)."""
    files: list[str] = ["<generated>"]
    out: list[str] = []
    _expand(relpath, root, files, out, stack=(), done=set())
    return ShaderSource("\n".join(out) + "\n", tuple(files))


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
    out.append(f"#line 1 {index}")
    for lineno, line in enumerate(path.read_text().splitlines(), start=1):
        m = _INCLUDE.match(line)
        if m:
            _expand(m.group(1), root, files, out, (*stack, relpath), done)
            out.append(f"#line {lineno + 1} {index}")
        else:
            out.append(line)


def map_compile_error(log: str, files: tuple[str, ...]) -> str:
    """Rewrite `<index>:<line>` locations in a compiler log to `gpu_shaders/<file>:<line>`."""

    def name(index: str) -> str | None:
        i = int(index)
        if 0 < i < len(files):
            return f"gpu_shaders/{files[i]}"
        return None

    mapped = []
    for line in log.splitlines():
        for pattern in _LOCATIONS:
            m = pattern.search(line)
            if m and name(m.group(1)):
                line = line[: m.start()] + f"{name(m.group(1))}:{m.group(2)}" + line[m.end() :]
                break
        mapped.append(line)
    return "\n".join(mapped)
