"""Argument checks shared by commands: each raises a BounceError so the CLI exits 2 with one line."""

from __future__ import annotations

import sys
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path

from ..engine.errors import ConfigError, SceneError


def existing_blend(path: str) -> Path:
    p = Path(path)
    if not p.is_file():
        raise SceneError(f"no such file: {path}")
    if p.suffix.lower() != ".blend":
        raise SceneError(f"not a .blend file: {path}")
    return p


def output_dir(path: str) -> Path:
    p = Path(path)
    try:
        p.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise ConfigError(f"cannot create output directory {path}: {exc.strerror}") from None
    return p


def _missing_dirs(path: Path) -> list[Path]:
    """`path` and its ancestors that do not exist yet, deepest first."""
    missing = []
    for p in (path, *path.parents):
        if p.exists() or p.is_symlink():
            break
        missing.append(p)
    return missing


@contextmanager
def removed_on_failure(path: str | None) -> Iterator[Callable[[int], None]]:
    """Run a command; if it raises, or reports failure through the callable yielded (its exit
    status), remove the directories of `path` that did not exist before and are empty: a failed run
    leaves nothing behind. A directory that existed before, or holds anything, is never touched."""
    missing = _missing_dirs(Path(path)) if path else []

    def cleanup() -> None:
        for d in missing:
            try:
                d.rmdir()  # only when empty, and only a directory
            except FileNotFoundError:
                continue  # never created (the run failed before): its parents may have been
            except OSError:
                break  # not empty or not ours: its parents are not empty either

    status = {"code": 0}
    try:
        yield lambda code: status.update(code=code)
    except BaseException:
        cleanup()
        raise
    if status["code"] != 0:
        cleanup()


def progress(quiet: bool) -> Callable[[str], None]:
    """A step reporter: each call prints 'bounce: <step>' on stderr (stdout stays machine-readable),
    nothing when quiet."""
    if quiet:
        return lambda step: None
    return lambda step: print(f"bounce: {step}", file=sys.stderr, flush=True)


def add_quiet(parser) -> None:
    parser.add_argument("--quiet", action="store_true", help="no progress on stderr")
