"""Light-update cost of several method settings as a multiple of the first's, measured in one process
so that the machine's load falls on all of them alike (docs/PROBES.md, "Area sampling of grazing
texels"):

    .venv/bin/python tools/update_ratio.py SCENE.blend --res 256 --rounds 9 \\
        lpv probes:probes.area_samples=1 probes:probes.area_samples=4

Each ROW is a method, optionally with bench-style settings (`group.field=value`, comma-separated). The
rows are set up once on the same captured scene, then timed in turn for --rounds rounds, as the benchmark
times its update costs (updates.update_costs_in_turn: each round one light update of each row, every light
moved 1 cm, no per-pass waits). Prints each row's median over the rounds (ms) and its multiple of the
first row's.
"""

from __future__ import annotations

import argparse
import ast
import json
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))


def parse_row(text: str) -> tuple[str, dict]:
    """'probes:probes.area_samples=4,probes.face_texels=9' -> ('probes', {...}); values as Python literals
    where they parse (numbers, True), else strings."""
    method, _, rest = text.partition(":")
    setting = {}
    for item in filter(None, rest.split(",")):
        key, _, value = item.partition("=")
        try:
            setting[key] = ast.literal_eval(value)
        except (ValueError, SyntaxError):
            setting[key] = value
    return method, setting


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("blend", type=Path)
    parser.add_argument("rows", nargs="+", help="method[:group.field=value,...]; the first is the baseline")
    parser.add_argument("--res", type=int, default=256)
    parser.add_argument("--bounces", type=int, default=1)
    parser.add_argument("--rounds", type=int, default=9)
    args = parser.parse_args()

    from addon.bridge.bench import make_configs
    from addon.bridge.pipeline import methods_in_turn_update_costs

    rows = [parse_row(text) for text in args.rows]
    costs = methods_in_turn_update_costs(
        args.blend, [make_configs(method, setting, args.res, args.bounces) for method, setting in rows], args.rounds)
    baseline = costs[0]["lights"]
    print(json.dumps({text: {"lights_ms": round(ms["lights"], 1), "x_first": round(ms["lights"] / baseline, 3)}
                      for text, ms in zip(args.rows, costs, strict=True)}, indent=1))


if __name__ == "__main__":
    main()
