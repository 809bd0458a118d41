"""`python -m addon bench [--scenes a,b] [--methods direct,rsm] [--quick] [--res N] [--ref-spp N] [--out DIR]`:
speed against error for every method x setting on every scene (see addon/bridge/bench.py).

Writes DIR/REPORT.md (the generated block between its markers; text outside them is kept) and
DIR/<scene>.png; caches scenes and Cycles references under --cache. Prints one JSON line at the end.
"""

from __future__ import annotations

import json
from pathlib import Path

from ..engine.errors import ConfigError
from ._args import output_dir

NAME = "bench"
HELP = "benchmark methods against Cycles: error vs time report (REPORT.md) and plots"


def _names(text: str | None) -> list[str] | None:
    if text is None:
        return None
    names = [n.strip() for n in text.split(",") if n.strip()]
    if not names:
        raise ConfigError(f"empty list: {text!r}")
    return names


def add_arguments(p) -> None:
    p.add_argument("--scenes", help="comma-separated scene names (default: all procedural + real scenes found)")
    p.add_argument("--methods", help="comma-separated methods (default: every implemented method)")
    p.add_argument("--quick", action="store_true",
                   help="CI size: reference 128 spp, Cycles curve 1/4/16 spp, 2 timed runs")
    p.add_argument("--res", type=int, default=128, help="long side in pixels (default 128)")
    p.add_argument("--ref-spp", type=int, help="reference samples per pixel (default 1024; --quick: 128)")
    p.add_argument("--bounces", type=int, default=1, help="diffuse bounces, 1..8 (default 1)")
    p.add_argument("--out", default="benchmarks", help="report directory (default benchmarks)")
    p.add_argument("--cache", default="out/bench", help="scenes, references and runs cache (default out/bench)")


def run(args) -> int:
    from ..bridge import bench
    from ..bridge.reference import check_settings

    scenes, methods = _names(args.scenes), _names(args.methods)
    ref_spp = args.ref_spp
    check_settings(ref_spp or bench.REF_SPP, args.bounces, args.res)  # before bpy is imported
    for m in methods or ():
        bench.settings_for(m)
    opt = bench.Options(
        scenes=scenes, methods=methods, quick=args.quick, res=args.res, ref_spp=ref_spp, bounces=args.bounces,
        out=output_dir(args.out), cache=Path(args.cache),
        command=bench.command_line(scenes, methods, args.quick, args.res, ref_spp, args.bounces, args.out,
                                   args.cache),
    )
    result = bench.run_bench(opt)
    print(json.dumps({"report": str(opt.out / "REPORT.md"), "scenes": [s["name"] for s in result["scenes"]],
                      "skipped": result["skipped"]}))
    return 0
