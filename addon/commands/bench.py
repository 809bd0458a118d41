"""`python -m addon bench [--scenes a,b] [--methods direct,rsm] [--settings-filter all|default] [--quick]
[--no-update-costs] [--anchors oidn,eevee] [--res N] [--ref-spp N] [--ref-noise X] [--out DIR]`: speed against
error for every method x setting on every scene, with each setting's update costs, against raw Cycles and the anchors
(see addon/bridge/bench.py and addon/bridge/anchors.py).

Writes DIR/REPORT.md (the generated block between its markers; text outside them is kept),
DIR/results.json (one record per scene x method x setting) and DIR/<scene>.png; caches scenes and Cycles
references under --cache. Prints one JSON line at the end.
"""

from __future__ import annotations

import contextlib
import json
import os
from pathlib import Path

from ..bridge.anchors import ANCHORS, DEFAULT_ANCHORS
from ..bridge.bench import REF_SPP_MAX, ROW_FILTERS  # bridge/bench.py imports without bpy
from ..engine.config import GIConfig
from ..engine.errors import ConfigError
from ._args import add_quiet, output_dir
from ._settings import add_field_flag

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
    p.add_argument("--settings-filter", default="all", choices=ROW_FILTERS,
                   help="which registry rows of each method run: all (default), or default = the row at the "
                        "method's default settings (one run per method and scene)")
    p.add_argument("--no-update-costs", action="store_true",
                   help="skip timing the full / lights / camera updates of each row (faster)")
    p.add_argument("--anchors", help=f"comma-separated anchors measured besides raw Cycles, of {', '.join(ANCHORS)} "
                                     f"(default {','.join(DEFAULT_ANCHORS)}): oidn = Cycles' curve denoised by "
                                     "Open Image Denoise; eevee = one EEVEE render per scene (about a minute or more "
                                     "per scene on a CPU rasteriser)")
    p.add_argument("--quick", action="store_true",
                   help="CI size: reference 128 spp, Cycles curve 1/4/16 spp, 2 timed runs")
    add_field_flag(p, GIConfig, "resolution", "--res", default=128, doc="long side in pixels")
    p.add_argument("--ref-spp", type=int, help="reference samples per pixel (default 1024; --quick: 128)")
    p.add_argument("--ref-noise", type=float,
                   help=f"raise each scene's reference spp (by powers of 2, at most {REF_SPP_MAX}) until the "
                        "rel_rmse_8 between two seeds' references is at most this (default: off, every scene at "
                        "--ref-spp)")
    add_field_flag(p, GIConfig, "bounces")
    p.add_argument("--out", default="benchmarks", help="report directory (default benchmarks)")
    p.add_argument("--cache", default="out/bench", help="scenes, references and runs cache (default out/bench)")
    add_quiet(p)


@contextlib.contextmanager
def _quiet_stderr(quiet: bool):
    """bridge/bench.py draws its progress bar on sys.stderr: --quiet sends it nowhere (skipped scenes
    are still listed in the JSON line and REPORT.md; errors are printed after the run)."""
    if not quiet:
        yield
        return
    with open(os.devnull, "w") as devnull, contextlib.redirect_stderr(devnull):
        yield


def run(args) -> int:
    from ..bridge import bench
    from ..bridge.reference import check_settings

    scenes, methods = _names(args.scenes), _names(args.methods)
    anchors = bench.resolve_anchors(_names(args.anchors))
    ref_spp = args.ref_spp
    check_settings(ref_spp or bench.REF_SPP, args.bounces, args.res)  # before bpy is imported
    if args.ref_noise is not None and not 0 < args.ref_noise < 1:
        raise ConfigError(f"--ref-noise must be in (0, 1): {args.ref_noise}")
    for m in methods or ():
        bench.settings_for(m)
    update_costs = not args.no_update_costs
    opt = bench.Options(
        scenes=scenes, methods=methods, quick=args.quick, res=args.res, ref_spp=ref_spp, ref_noise=args.ref_noise,
        bounces=args.bounces, update_costs=update_costs, row_filter=args.settings_filter, anchors=anchors,
        out=output_dir(args.out), cache=Path(args.cache),
        command=bench.command_line(scenes, methods, args.quick, args.res, ref_spp, args.bounces, args.out,
                                   args.cache, update_costs, args.settings_filter, anchors, args.ref_noise),
    )
    with _quiet_stderr(args.quiet):
        result = bench.run_bench(opt)
    print(json.dumps({"report": str(opt.out / "REPORT.md"), "results": str(opt.out / "results.json"),
                      "scenes": [s["name"] for s in result["scenes"]],
                      "skipped": result["skipped"]}))
    return 0
