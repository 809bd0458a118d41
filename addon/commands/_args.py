"""Argument checks shared by commands: each raises a BounceError so the CLI exits 2 with one line."""

from __future__ import annotations

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
