"""`python -m addon bake F.blend --out DIR ...`: lightmaps (EXR per object) or vertex colours."""

from __future__ import annotations

from pathlib import Path

from ..engine.config import GIConfig, RsmConfig
from ..engine.errors import SceneError
from ..engine.lightmap import PASSES, TARGETS, check_choice, parse_shard
from ._args import existing_blend

NAME = "bake"
HELP = ("bake direct/indirect light per texel (DIR/<object>_<pass>.exr) or per mesh corner (colour attribute "
        "bounce_<pass>); DIR/bake.json summarises")


def add_arguments(p) -> None:
    p.add_argument("blend", help=".blend file (never modified)")
    p.add_argument("--out", required=True, help="output directory (created if its parent exists)")
    p.add_argument("--objects", default=None, help="comma-separated object names (default: every mesh object)")
    p.add_argument("--size", type=int, default=512, help="lightmap side in texels")
    p.add_argument("--method", default="rsm", help="GI method (rsm, direct, ...)")
    p.add_argument("--pass", dest="pass_name", default="indirect", help="indirect, direct or combined (= both)")
    p.add_argument("--target", default="image", help="image (EXR per object) or vertex-colors")
    p.add_argument("--overwrite", action="store_true", help="replace existing files (default: skip them)")
    p.add_argument("--shard", default=None, help="i/n: bake every n-th object (sorted names) starting at i")
    p.add_argument("--save-blend", default=None, help="vertex-colors: save a copy of the .blend with the attributes")
    p.add_argument("--margin", type=int, default=16, help="texels of seam dilation around UV islands")
    p.add_argument("--rsm-res", type=int, default=256, help="RSM side in texels")
    p.add_argument("--vpl-samples", type=int, default=256, help="VPLs gathered per texel (rsm)")
    p.add_argument("--visibility", default="voxel", help="VPL visibility for rsm: none or voxel")
    p.add_argument("--voxel-cells", type=int, default=64, help="voxel cells along the longest side")
    p.add_argument("--seed", type=int, default=0)
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
    blend = existing_blend(args.blend)
    objects = None
    if args.objects is not None:
        objects = [n for n in (s.strip() for s in args.objects.split(",")) if n]
        if not objects:
            raise SceneError("--objects names no object")
    from ..bridge.bake import bake_file  # imports bpy: only when actually baking

    summary = bake_file(blend, Path(args.out), objects, args.size, gi, rsm, args.pass_name, args.target,
                        args.overwrite, index, count, Path(args.save_blend) if args.save_blend else None,
                        args.margin, progress=not args.quiet)
    failed = [n for n, r in summary["objects"].items() if r["status"] == "error"]
    if failed:
        print(f"error: {len(failed)} of {len(summary['objects'])} objects failed ({', '.join(failed)}); "
              f"see {Path(args.out) / 'bake.json'}", file=sys.stderr)
        return 2
    return 0
