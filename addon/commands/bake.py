"""`python -m addon bake F.blend [G.blend ...] --out DIR ...`: lightmaps (EXR per object), vertex
colours, the LPV's SH volume, or the probe grid. With several files each gets its own DIR/<file stem>/ and bake.json,
and DIR/bake.json lists them: one run bakes a whole set of .blend files (a farm job shards objects).

Every config field has a flag (commands/_settings.py) with the scene settings' default. Every argument
is checked before a file is opened or written."""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from ..engine.config import GIConfig
from ..engine.errors import ConfigError, SceneError
from ..engine.lightmap import (
    IMAGE_SIZE_TEXELS,
    PASSES,
    TARGETS,
    VOLUME_TARGETS,
    check_choice,
    check_supersample,
    parse_shard,
    safe_name,
)
from ._args import existing_blend
from ._settings import add_budget_flags, add_config_flags, budget, check_bounces, configs, given

NAME = "bake"
HELP = ("bake direct/indirect light per texel (DIR/<object>_<pass>.exr) or per mesh corner (colour attribute "
        "bounce_<pass>); DIR/bake.json summarises")


def add_arguments(p) -> None:
    p.add_argument("blend", nargs="+", help=".blend file(s) (never modified)")
    p.add_argument("--out", required=True, help="output directory (created if its parent exists)")
    p.add_argument("--objects", default=None, help="comma-separated object names (default: every mesh object)")
    p.add_argument("--size", type=int, default=None,
                   help="lightmap side in texels (default: 512; --target image and vertex-colors' G-buffer)")
    p.add_argument("--pass", dest="pass_name", default="indirect", help="indirect, direct or combined (= both)")
    p.add_argument("--target", default="image",
                   help="image (EXR per object), vertex-colors (needs --save-blend), volume (the LPV's SH grid: "
                        "--method lpv, the default there) or probes (the probe grid's EXR atlases and layout: "
                        "--method probes, the default there)")
    p.add_argument("--overwrite", action="store_true", help="replace existing files (default: skip them)")
    p.add_argument("--shard", default=None, help="i/n: bake every n-th object (sorted names) starting at i")
    p.add_argument("--save-blend", default=None, help="vertex-colors: save a copy of the .blend with the attributes")
    p.add_argument("--margin", type=int, default=16, help="texels of seam dilation around UV islands")
    p.add_argument("--supersample", type=int, default=1,
                   help="sub-texels per texel side (--target image): each texel the mean light over its "
                        "covered sub-texels, as Cycles' bake averages over the texel; N x N times the work")
    p.add_argument("--self-check", action="store_true",
                   help="also estimate each lightmap's rel_rmse_8 against Cycles' bake of the object: two Cycles "
                        "bakes of a few samples, their own noise subtracted (bake.json objects.*.self_check; "
                        "--target image)")
    p.add_argument("--verify", action=argparse.BooleanOptionalAction, default=None,
                   help="with --method auto --error-budget E and --target image (on by default there): bake the "
                        "candidate settings (fastest first) on the largest objects, judge each lightmap by the "
                        "--self-check's path-traced check, and take the first whose every lightmap is within E "
                        "(bake.json choice.verified); --no-verify: the model's choice, unchecked")
    p.add_argument("--quiet", action="store_true", help="no progress on stderr")
    add_config_flags(p)
    add_budget_flags(p)


def _objects(text: str | None) -> list[str] | None:
    if text is None:
        return None
    names = [n for n in (s.strip() for s in text.split(",")) if n]
    if not names:
        raise SceneError("--objects names no object")
    return names


def _check_target(args) -> None:
    """What a target needs, refused once before anything is loaded."""
    if args.target in VOLUME_TARGETS:
        method = VOLUME_TARGETS[args.target]
        what = {"volume": "the LPV's grid", "probes": "the probe grid"}[args.target]
        if given(args, "method") and args.method != method:
            raise ConfigError(f"--target {args.target} bakes {what}: use --method {method} "
                              f"(got --method {args.method})")
        if args.size is not None:
            raise ConfigError(f"--size has no meaning with --target {args.target} (one {what} per scene)")
        if args.verify:
            raise ConfigError(f"--verify judges lightmap images (--target image), not {what}")
    elif args.target == "vertex-colors" and not args.save_blend:
        raise ConfigError("--target vertex-colors writes colour attributes into a copy of the .blend: "
                          "give --save-blend OUT.blend (the input file is never modified)")


def _check_pass(gi: GIConfig, pass_name: str) -> None:
    from ..engine import methods

    if pass_name != "direct" and "indirect" not in methods.get(gi.method).products:
        raise ConfigError(f"--pass {pass_name} needs indirect light: --method {gi.method} computes direct light "
                          "only (use --pass direct or another method)")


def run(args) -> int:
    check_choice(args.pass_name, PASSES, "--pass")
    check_choice(args.target, TARGETS, "--target")
    _check_target(args)
    index, count = parse_shard(args.shard)
    volume = VOLUME_TARGETS.get(args.target)  # the method a per-scene target bakes, else None
    chosen_for = budget(args)
    settings = configs(args, **({"method": volume} if volume else {}))
    gi = settings["gi"]
    if chosen_for is None:
        check_bounces(gi)
    if not volume:
        _check_pass(gi, args.pass_name)
    if args.size is not None and not 8 <= args.size <= 8192:
        raise ConfigError(f"--size {args.size}: out of range [8, 8192]")
    if not 0 <= args.margin <= 1024:
        raise SceneError(f"--margin must be in 0..1024, got {args.margin}")
    if args.supersample != 1 and args.target != "image":
        raise ConfigError(f"--supersample is for --target image (got --target {args.target})")
    if args.self_check and args.target != "image":
        raise ConfigError(f"--self-check judges lightmap images: it is for --target image (got --target {args.target})")
    check_supersample(args.supersample, IMAGE_SIZE_TEXELS if args.size is None else args.size)
    blends = [existing_blend(b) for b in args.blend]
    if len(blends) > 1 and args.save_blend:
        raise SceneError("--save-blend takes one input file")
    objects = _objects(args.objects)
    from ..bridge.bake import bake_file, bake_probes, bake_volume  # imports bpy: only when actually baking

    out = Path(args.out)
    if volume:
        bake = bake_volume if args.target == "volume" else bake_probes
        for blend in blends:
            bake(blend, out, settings, args.overwrite, progress=not args.quiet)
        return 0
    failed, files = [], {}
    for blend in blends:
        # One file: DIR itself (as before); several: DIR/<stem>/ so equal object names never collide.
        file_out = out if len(blends) == 1 else out / safe_name(blend.stem)
        if len(blends) > 1:
            out.mkdir(parents=True, exist_ok=True)
        summary = bake_file(blend, file_out, objects, args.size, settings, args.pass_name, args.target,
                            args.overwrite, index, count, Path(args.save_blend) if args.save_blend else None,
                            args.margin, progress=not args.quiet, budget=chosen_for, supersample=args.supersample,
                            self_check=args.self_check, verify=args.verify)
        files[str(blend)] = str(file_out / "bake.json")
        failed += [f"{blend.name}:{n}" for n, r in summary["objects"].items() if r["status"] == "error"]
    if len(blends) > 1:
        (out / "bake.json").write_text(json.dumps({"files": files}, indent=2))
    if failed:
        print(f"error: {len(failed)} objects failed ({', '.join(failed)}); see the bake.json files in {out}",
              file=sys.stderr)
        return 2
    return 0
