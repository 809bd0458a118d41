"""`python -m addon render F.blend --method M --out DIR [--res N]`: run a method headless."""

from __future__ import annotations

import argparse
import json

from ..engine.config import GIConfig, LpvConfig, RsmConfig, VctConfig
from ._args import existing_blend, output_dir

NAME = "render"
HELP = "render a .blend with a Bounce method: DIR/direct.exr, DIR/indirect.exr (indirect methods), stats.json"


def add_arguments(p) -> None:
    p.add_argument("blend", help=".blend file with a camera")
    p.add_argument("--method", default="direct", help="GI method (direct, rsm, ...)")
    p.add_argument("--out", required=True, help="output directory")
    p.add_argument("--res", type=int, default=256, help="long side of the image in pixels (camera aspect kept)")
    p.add_argument("--bounces", type=int, default=1)
    p.add_argument("--rsm-res", type=int, default=256, help="RSM side in texels")
    p.add_argument("--vpl-samples", type=int, default=256, help="VPLs gathered per pixel (rsm)")
    p.add_argument("--visibility", default="none", help="VPL visibility for rsm: none or voxel")
    p.add_argument("--voxel-cells", type=int, default=64, help="voxel cells along the longest side (rsm, vct)")
    p.add_argument("--grid", type=int, default=32, help="LPV cells along the longest side (lpv)")
    p.add_argument("--iterations", type=int, default=16, help="LPV propagation steps (lpv, classic)")
    p.add_argument("--variant", default="improved", help="LPV transport: improved or classic (the published one)")
    p.add_argument("--geometry-volume", action=argparse.BooleanOptionalAction, default=True,
                   help="LPV: occlude by the voxelized surfaces (default on)")
    p.add_argument("--surface-offsets", action=argparse.BooleanOptionalAction, default=True,
                   help="LPV geometry volume: a surface blocks the transfers on its side of its cell (default on)")
    p.add_argument("--far-field", action=argparse.BooleanOptionalAction, default=True,
                   help="LPV: run the near steps on the grid, the rest on a grid of twice the cell (default on)")
    p.add_argument("--emitter-classes", action=argparse.BooleanOptionalAction, default=False,
                   help="LPV: a surface reads no light from surfaces facing its way (six propagations)")
    p.add_argument("--near-steps", type=int, default=0, help="LPV far field: the grid's own steps (0: half its cells)")
    p.add_argument("--cascades", type=int, default=1, help="LPV: nested grids, the finest around the camera")
    p.add_argument("--cell-size", type=float, default=0.0,
                   help="LPV: finest cascade's cell in metres (0: the coarsest grid fits the scene)")
    p.add_argument("--cones", type=int, default=16, help="diffuse cones per gather point (vct)")
    p.add_argument("--step-ratio", type=float, default=1.0, help="cone march step / sampled voxel size (vct)")
    p.add_argument("--cone-offset", type=float, default=1.5, help="cone origins off the surface, in cells (vct)")
    p.add_argument("--radiance", default="anisotropic", help="voxel radiance: anisotropic or isotropic (vct)")
    p.add_argument("--gather-scale", type=int, default=1,
                   help="cones at one pixel per n x n block, upsampled along edges (vct)")
    p.add_argument("--filtered-injection", action=argparse.BooleanOptionalAction, default=False,
                   help="vct: share each VPL between the 2 x 2 nearest cells along its surface (no flicker as "
                        "lights move; slower)")
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--repeat", type=int, default=3, help="timed runs after a warm-up (median reported)")


def run(args) -> int:
    gi = GIConfig(method=args.method, bounces=args.bounces, resolution=args.res, seed=args.seed)
    rsm = RsmConfig(resolution=args.rsm_res, vpl_samples=args.vpl_samples, visibility=args.visibility,
                    voxel_cells=args.voxel_cells)
    lpv = LpvConfig(grid_cells=args.grid, iterations=args.iterations, variant=args.variant,
                    geometry_volume=args.geometry_volume, surface_offsets=args.surface_offsets,
                    far_field=args.far_field, near_steps=args.near_steps, emitter_classes=args.emitter_classes,
                    cascades=args.cascades, cell_size_m=args.cell_size)
    vct = VctConfig(voxel_cells=args.voxel_cells, diffuse_cones=args.cones, step_ratio=args.step_ratio,
                    offset_cells=args.cone_offset, radiance=args.radiance, gather_scale=args.gather_scale,
                    filtered_injection=args.filtered_injection)
    blend = existing_blend(args.blend)
    out = output_dir(args.out)
    from ..bridge.pipeline import render_file  # imports bpy: only when actually rendering

    stats = render_file(blend, out, gi, rsm, repeat=max(1, args.repeat), lpv=lpv, vct=vct)
    print(json.dumps({"out": str(out), "total_ms": round(stats["total_ms"], 2), "notes": stats["notes"]}))
    return 0
