"""`python -m addon render F.blend --out DIR [--method M] [--res N] ...`: run a method headless.

Every GIConfig, RsmConfig, LpvConfig and VctConfig field has a flag (commands/_settings.py) with the
scene settings' default.
"""

from __future__ import annotations

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
    p.add_argument("--verify", action="store_true",
                   help="with --method auto --error-budget E: render the candidate settings (fastest first) on "
                        "this scene, judge each by the --self-check's path-traced check, and take the first "
                        "within E (stats.json choice.verified; costs those renders once)")
    add_quiet(p)
    add_config_flags(p)
    add_budget_flags(p)


def run(args) -> int:
    settings = configs(args)
    chosen_for = budget(args)
    if args.verify and not (chosen_for and "error_budget" in chosen_for):
        raise ConfigError("--verify checks the choice for an error budget: give it with --method auto --error-budget E")
    if chosen_for is None:
        check_bounces(settings["gi"])
    blend = existing_blend(args.blend)
    out = output_dir(args.out)
    from ..bridge.pipeline import render_file  # imports bpy: only when actually rendering

    stats = render_file(blend, out, settings, repeat=max(1, args.repeat), progress=progress(args.quiet),
                        profile_updates=args.profile_updates, budget=chosen_for, self_check=args.self_check,
                        verify=args.verify)
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
