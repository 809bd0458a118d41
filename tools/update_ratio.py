"""Light-update cost of several method settings as a multiple of the first's, measured in one process
so that the machine's load falls on all of them alike (docs/PROBES.md, "Area sampling of grazing
texels"):

    .venv/bin/python tools/update_ratio.py SCENE.blend --res 256 --rounds 3 \\
        lpv probes:probes.area_samples=1 probes:probes.area_samples=4

Each ROW is a method, optionally with bench-style settings (`group.field=value`, comma-separated). The
rows are set up once, then timed in turn for --rounds rounds: each round takes updates.update_costs'
median of 5 light updates (every light moved 1 cm and back, no per-pass waits). Prints each row's
per-round medians (ms) and the median over rounds as a multiple of the first row's.
"""

from __future__ import annotations

import argparse
import ast
import json
import statistics
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
    parser.add_argument("--rounds", type=int, default=3)
    args = parser.parse_args()

    import bpy

    from addon.bridge import pipeline
    from addon.bridge.bench import make_configs
    from addon.bridge.capture import SceneCache, image_size
    from addon.engine import methods
    from addon.engine.updates import update_costs

    pipeline.open_blend(args.blend)
    width, height = image_size(bpy.context.scene, args.res)
    scene = SceneCache().update(bpy.context.evaluated_depsgraph_get(), width, height)
    backend = pipeline.backend()
    rows = {}
    for text in args.rows:
        method_name, setting = parse_row(text)
        method = methods.create(backend, make_configs(method_name, setting, args.res, args.bounces))
        method.set_scene(scene)
        method.run()  # the warm-up: shaders compiled, the light field solved once
        rows[text] = method
    light_ms = {text: [] for text in rows}
    for _ in range(args.rounds):
        for text, method in rows.items():
            light_ms[text].append(update_costs(method, 5)["lights"])
    baseline = statistics.median(light_ms[args.rows[0]])
    print(json.dumps({text: {"lights_ms": [round(ms, 1) for ms in values],
                             "x_first": round(statistics.median(values) / baseline, 3)}
                      for text, values in light_ms.items()}, indent=1))


if __name__ == "__main__":
    main()
