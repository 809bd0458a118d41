"""`python -m addon scene NAME --out FILE.blend`: write a procedural benchmark scene; `--list` names them."""

from __future__ import annotations

import os
from pathlib import Path

from ..engine.errors import ConfigError, SceneError

NAME = "scene"
HELP = "write a procedural benchmark scene (cornell, window-room, ...) to a .blend file"


def add_arguments(parser) -> None:
    parser.add_argument("name", nargs="?", metavar="NAME", help="a scene name (see --list)")
    parser.add_argument("--out", metavar="FILE.blend", help="the .blend file to write")
    parser.add_argument("--list", action="store_true", help="print the scene names, one per line")


def _check_out(out: str | None) -> Path:
    if not out:
        raise ConfigError("--out FILE.blend is required")
    path = Path(out)
    if path.suffix.lower() != ".blend":
        raise ConfigError(f"not a .blend path: {out}")
    parent = path.parent if str(path.parent) else Path(".")
    if not parent.is_dir():
        raise SceneError(f"cannot write {out}: no such directory {parent}")
    if path.is_dir() or not os.access(parent, os.W_OK) or (path.exists() and not os.access(path, os.W_OK)):
        raise SceneError(f"cannot write {out}: permission denied or not a file")
    return path


def run(args) -> int:
    from ..bridge import scenes  # imports bpy (~1 s): only here, so `--help` stays fast

    if args.list:
        print("\n".join(scenes.SCENES))
        return 0
    if args.name not in scenes.SCENES:
        given = "no scene name given" if args.name is None else f"unknown scene {args.name!r}"
        raise ConfigError(f"{given}; known: {', '.join(scenes.SCENES)}")
    path = _check_out(args.out)  # before building, so a bad path costs nothing
    scenes.save(args.name, path)
    print(path)
    return 0
