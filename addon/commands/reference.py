"""`python -m addon reference F.blend --out DIR`: the Cycles reference (see addon/bridge/reference.py).

Writes DIR/indirect.exr, direct.exr, albedo.exr (with --glossy also glossy.exr; RGBA, A = geometry mask)
and DIR/stats.json, and prints stats.json's content as one JSON line (the last line of stdout: Blender
logs before it). --res, --bounces and --seed have GIConfig's limits (a reference is what a method is
measured against).
"""

from __future__ import annotations

import json

from ..engine.config import GIConfig
from ._args import add_quiet, existing_blend, output_dir, progress
from ._settings import add_field_flag

NAME = "reference"
HELP = "render the Cycles reference passes (Diffuse Indirect/Direct/Color) of a .blend"


def add_arguments(parser) -> None:
    parser.add_argument("blend", help=".blend file with a camera")
    parser.add_argument("--out", required=True, help="output directory")
    parser.add_argument("--spp", type=int, default=1024, help="samples per pixel (default 1024)")
    add_field_flag(parser, GIConfig, "bounces")
    add_field_flag(parser, GIConfig, "resolution", "--res",
                   doc="long side in pixels; the camera's aspect is kept")
    add_field_flag(parser, GIConfig, "seed", doc="Cycles seed")
    parser.add_argument("--glossy", action="store_true",
                        help="also glossy.exr: Glossy Color x Glossy Indirect after one glossy bounce")
    add_quiet(parser)


def run(args) -> int:
    # Check everything before importing bpy (slow) or creating the output directory.
    from ..bridge.reference import check_settings, render_reference

    check_settings(args.spp, args.bounces, args.res, args.seed)
    blend = existing_blend(args.blend)
    out = output_dir(args.out)
    stats = render_reference(blend, out, args.spp, args.bounces, args.res, args.seed, args.glossy,
                             progress=progress(args.quiet))
    print(json.dumps(stats))
    return 0
