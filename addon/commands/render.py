"""`python -m addon render F.blend --out DIR [--method M] [--res N] ...`: run a method headless.

Every GIConfig, RsmConfig, LpvConfig and VctConfig field has a flag (commands/_settings.py) with the
scene settings' default.
"""

from __future__ import annotations

import argparse
import json

from ..engine.errors import ConfigError
from ._args import add_quiet, existing_blend, output_dir, progress
from ._settings import add_budget_flags, add_config_flags, budget, check_bounces, configs

NAME = "render"
HELP = "render a .blend with a Bounce method: DIR/direct.exr, DIR/indirect.exr (indirect methods), stats.json"


def add_arguments(p) -> None:
    p.add_argument("blend", help=".blend file with a camera")
    p.add_argument("--out", required=True, help="output directory")
    p.add_argument("--repeat", type=int, default=3, help="timed runs after a warm-up (median reported)")
    p.add_argument("--profile-updates", action="store_true",
                   help="also time the three kinds of update (a geometry change: everything; every light moved 1 cm; "
                        "the camera moved 1 cm): stats.json update_ms = {full, lights, camera}, medians of --repeat")
    p.add_argument("--self-check", action="store_true",
                   help="also estimate the indirect light's rel_rmse_8 against Cycles on this scene: two Cycles "
                        "renders of a few samples, their own noise subtracted (stats.json self_check; costs those "
                        "renders, seconds at preview sizes)")
    # On by default with an error budget: held out, the model alone met E = 0.2 on 9 of the 15 benchmark
    # scenes, verified on 12 (benchmarks/choice/REPORT.md); a budget the choice does not check is one a
    # user cannot rely on. --no-verify takes the model's choice at no cost.
    p.add_argument("--verify", action=argparse.BooleanOptionalAction, default=None,
                   help="with --method auto --error-budget E (on by default there): render the candidate "
                        "settings (fastest first) on this scene, judge each by the --self-check's path-traced "
                        "check, and take the first within E (stats.json choice.verified; costs those renders "
                        "once, seconds at preview sizes); --no-verify: the model's choice, unchecked")
    add_quiet(p)
    add_config_flags(p)
    add_budget_flags(p)


def run(args) -> int:
    settings = configs(args)
    chosen_for = budget(args)
    error_budget = bool(chosen_for and "error_budget" in chosen_for)
    if args.verify and not error_budget:
        raise ConfigError("--verify checks the choice for an error budget: give it with --method auto --error-budget E")
    verify = error_budget if args.verify is None else args.verify
    if chosen_for is None:
        check_bounces(settings["gi"])
    blend = existing_blend(args.blend)
    out = output_dir(args.out)
    from ..bridge.pipeline import render_file  # imports bpy: only when actually rendering

    stats = render_file(blend, out, settings, repeat=max(1, args.repeat), progress=progress(args.quiet),
                        profile_updates=args.profile_updates, budget=chosen_for, self_check=args.self_check,
                        verify=verify)
    summary = {"out": str(out), "total_ms": round(stats["total_ms"], 2), "notes": stats["notes"]}
    if "choice" in stats:
        summary["choice"] = {k: stats["choice"][k] for k in ("method", "setting", "why")}
    if stats.get("estimated_rel_rmse_8") is not None:
        summary["estimated_rel_rmse_8"] = round(stats["estimated_rel_rmse_8"], 3)
    if "self_check" in stats:
        summary["self_check"] = stats["self_check"]
    if "update_ms" in stats:
        summary["update_ms"] = {k: round(v, 2) for k, v in stats["update_ms"].items()}
    print(json.dumps(summary))
    return 0
