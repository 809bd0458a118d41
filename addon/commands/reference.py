"""`python -m addon reference F.blend --out DIR`: the Cycles reference (see addon/bridge/reference.py).

Writes DIR/indirect.exr, direct.exr, albedo.exr (with --glossy also glossy.exr; RGBA, A = geometry mask)
and DIR/stats.json, and prints stats.json's content as one JSON line (the last line of stdout: Blender
logs before it).
"""

from __future__ import annotations

import json

from ._args import existing_blend, output_dir

NAME = "reference"
HELP = "render the Cycles reference passes (Diffuse Indirect/Direct/Color) of a .blend"


def add_arguments(parser) -> None:
    parser.add_argument("blend", help=".blend file with a camera")
    parser.add_argument("--out", required=True, help="output directory")
    parser.add_argument("--spp", type=int, default=1024, help="samples per pixel (default 1024)")
    parser.add_argument("--bounces", type=int, default=1, help="diffuse bounces, 1..8 (default 1)")
    parser.add_argument("--res", type=int, default=256,
                        help="long side in pixels, 8..8192; the camera's aspect is kept (default 256)")
    parser.add_argument("--seed", type=int, default=0, help="Cycles seed (default 0)")
    parser.add_argument("--glossy", action="store_true",
                        help="also glossy.exr: Glossy Color x Glossy Indirect after one glossy bounce")


def run(args) -> int:
    # Check everything before importing bpy (slow) or creating the output directory.
    from ..bridge.reference import check_settings, render_reference

    check_settings(args.spp, args.bounces, args.res)
    blend = existing_blend(args.blend)
    out = output_dir(args.out)
    stats = render_reference(blend, out, args.spp, args.bounces, args.res, args.seed, args.glossy)
    print(json.dumps(stats))
    return 0
