"""`python -m addon bake F.blend [G.blend ...] --out DIR ...`: lightmaps (EXR per object), vertex
colours, or the LPV's SH volume. With several files each gets its own DIR/<file stem>/ and bake.json,
and DIR/bake.json lists them: one run bakes a whole set of .blend files (a farm job shards objects)."""

from __future__ import annotations

import argparse
import json
from pathlib import Path

from ..engine.config import GIConfig, LpvConfig, RsmConfig, VctConfig
from ..engine.errors import SceneError
from ..engine.lightmap import PASSES, TARGETS, check_choice, parse_shard, safe_name
from ._args import existing_blend

NAME = "bake"
HELP = ("bake direct/indirect light per texel (DIR/<object>_<pass>.exr) or per mesh corner (colour attribute "
        "bounce_<pass>); DIR/bake.json summarises")


def add_arguments(p) -> None:
    p.add_argument("blend", nargs="+", help=".blend file(s) (never modified)")
    p.add_argument("--out", required=True, help="output directory (created if its parent exists)")
    p.add_argument("--objects", default=None, help="comma-separated object names (default: every mesh object)")
    p.add_argument("--size", type=int, default=512, help="lightmap side in texels")
    p.add_argument("--method", default="rsm", help="GI method (rsm, direct, ...)")
    p.add_argument("--pass", dest="pass_name", default="indirect", help="indirect, direct or combined (= both)")
    p.add_argument("--target", default="image",
                   help="image (EXR per object), vertex-colors, or volume (the LPV's SH grid, --method lpv)")
    p.add_argument("--overwrite", action="store_true", help="replace existing files (default: skip them)")
    p.add_argument("--shard", default=None, help="i/n: bake every n-th object (sorted names) starting at i")
    p.add_argument("--save-blend", default=None, help="vertex-colors: save a copy of the .blend with the attributes")
    p.add_argument("--margin", type=int, default=16, help="texels of seam dilation around UV islands")
    p.add_argument("--rsm-res", type=int, default=256, help="RSM side in texels")
    p.add_argument("--vpl-samples", type=int, default=256, help="VPLs gathered per texel (rsm)")
    p.add_argument("--visibility", default="voxel", help="VPL visibility for rsm: none or voxel")
    p.add_argument("--voxel-cells", type=int, default=64, help="voxel cells along the longest side")
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--grid", type=int, default=32, help="LPV cells along the longest side (lpv)")
    p.add_argument("--variant", default="improved", help="LPV transport: classic or improved (lpv)")
    p.add_argument("--emitter-classes", action=argparse.BooleanOptionalAction, default=False,
                   help="LPV: a surface reads no light from surfaces facing its way (six propagations)")
    p.add_argument("--quiet", action="store_true", help="no progress bar")


def run(args) -> int:
    import sys

    check_choice(args.pass_name, PASSES, "--pass")
    check_choice(args.target, TARGETS, "--target")
    index, count = parse_shard(args.shard)
    gi = GIConfig(method=args.method, seed=args.seed)
    rsm = RsmConfig(resolution=args.rsm_res, vpl_samples=args.vpl_samples, visibility=args.visibility,
                    voxel_cells=args.voxel_cells)
    if not 0 <= args.margin <= 1024:
        raise SceneError(f"--margin must be in 0..1024, got {args.margin}")
    blends = [existing_blend(b) for b in args.blend]
    if len(blends) > 1 and args.save_blend:
        raise SceneError("--save-blend takes one input file")
    objects = None
    if args.objects is not None:
        objects = [n for n in (s.strip() for s in args.objects.split(",")) if n]
        if not objects:
            raise SceneError("--objects names no object")
    from ..bridge.bake import bake_file, bake_volume  # imports bpy: only when actually baking

    out = Path(args.out)
    lpv = LpvConfig(grid_cells=args.grid, variant=args.variant, geometry_volume=True,
                    emitter_classes=args.emitter_classes)
    vct = VctConfig(voxel_cells=args.voxel_cells)
    if args.target == "volume":
        gi = GIConfig(method="lpv", seed=args.seed)
        for blend in blends:
            bake_volume(blend, out, gi, rsm, lpv, args.overwrite)
        return 0
    failed, files = [], {}
    for blend in blends:
        # One file: DIR itself (as before); several: DIR/<stem>/ so equal object names never collide.
        file_out = out if len(blends) == 1 else out / safe_name(blend.stem)
        if len(blends) > 1:
            out.mkdir(parents=True, exist_ok=True)
        summary = bake_file(blend, file_out, objects, args.size, gi, rsm, args.pass_name, args.target,
                            args.overwrite, index, count, Path(args.save_blend) if args.save_blend else None,
                            args.margin, progress=not args.quiet, lpv=lpv, vct=vct)
        files[str(blend)] = str(file_out / "bake.json")
        failed += [f"{blend.name}:{n}" for n, r in summary["objects"].items() if r["status"] == "error"]
    if len(blends) > 1:
        (out / "bake.json").write_text(json.dumps({"files": files}, indent=2))
    if failed:
        print(f"error: {len(failed)} objects failed ({', '.join(failed)}); see the bake.json files in {out}",
              file=sys.stderr)
        return 2
    return 0
