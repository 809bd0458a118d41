"""Command-line dispatcher. Each sub-command is a module in addon/commands/ with
NAME, HELP, add_arguments(parser) and run(args) -> int; modules import bpy lazily inside run().

Exit status: 0 success; 2 with one line on stderr for a BounceError (bad input); 1 for internal errors.
A run that fails removes the output directory (--out) it created, when that is still empty.
"""

from __future__ import annotations

import argparse
import importlib
import pkgutil
import sys

from . import commands
from .commands._args import removed_on_failure
from .commands._settings import in_flag_terms
from .engine.errors import BounceError


def _command_modules():
    for info in sorted(pkgutil.iter_modules(commands.__path__), key=lambda m: m.name):
        if not info.name.startswith("_"):
            yield importlib.import_module(f"{commands.__name__}.{info.name}")


class _Parser(argparse.ArgumentParser):
    def error(self, message):  # argparse's default prints usage; the contract is one line and exit 2
        print(f"error: {message}", file=sys.stderr)
        raise SystemExit(2)


def build_parser() -> argparse.ArgumentParser:
    parser = _Parser(prog="python -m addon", description="Bounce: indirect light, measured against Cycles")
    sub = parser.add_subparsers(dest="command", required=True, parser_class=_Parser)
    for module in _command_modules():
        p = sub.add_parser(module.NAME, help=module.HELP, description=module.HELP)
        module.add_arguments(p)
        p.set_defaults(_run=module.run)
    return parser


def main(argv: list[str] | None = None) -> int:
    try:
        args = build_parser().parse_args(argv)
    except SystemExit as exc:  # a bad flag (one line printed by _Parser) or --help: the status, as for a run
        return int(exc.code or 0)
    with removed_on_failure(getattr(args, "out", None)) as report_status:
        try:
            code = int(args._run(args) or 0)
        except BounceError as exc:
            print(f"error: {in_flag_terms(str(exc))}", file=sys.stderr)
            code = 2
        report_status(code)
    return code
