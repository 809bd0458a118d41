"""Bounce's bake against Cycles' bake curve: texel-space error vs time, and the Cycles-equivalent
speed-up (time Cycles' bake needs to reach our rel_rmse_8 / our bake time), on a procedural scene (the
Cornell box by default).

    .venv/bin/python tools/bake_speedup.py [--scene cornell] [--objects Floor BackWall] [--size 64] \
        [--pass indirect|direct] [--method rsm|lpv|vct|...] [--emitter-classes] [--sky-rays N] \\
        [--supersample K] > table.md

Reference: a Cycles bake at --ref-spp (seed 0); Cycles' curve: bakes at increasing spp with seed 1;
Bounce: --method (rsm with voxel visibility by default; the others at their defaults; `direct` for
--pass direct), per object (setup = capture, upload and voxelization, once per file, reported apart).
Prints a Markdown table for benchmarks/REPORT.md.
"""

from __future__ import annotations

import argparse
import sys
import tempfile
from dataclasses import replace
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

OBJECTS = ("Floor", "BackWall")  # the Cornell box's


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scene", default="cornell", help="a procedural scene (python -m addon scene --list)")
    ap.add_argument("--objects", nargs="+", default=list(OBJECTS), help="the scene's objects to bake")
    ap.add_argument("--size", type=int, default=64)
    ap.add_argument("--ref-spp", type=int, default=1024)
    ap.add_argument("--pass", dest="pass_name", default="indirect", choices=("indirect", "direct"))
    from addon.engine import registry

    ap.add_argument("--method", default="rsm", choices=[m.name for m in registry.METHODS])
    ap.add_argument("--emitter-classes", action="store_true", help="lpv: LpvConfig.emitter_classes")
    ap.add_argument("--sky-rays", type=int, default=None, help="RsmConfig.sky_rays (default: its default)")
    ap.add_argument("--supersample", type=int, default=1, help="sub-texels per texel side (bake --supersample)")
    args = ap.parse_args()
    if args.pass_name not in registry.get(args.method).products:
        ap.error(f"--method {args.method} does not compute --pass {args.pass_name}")

    import bpy

    from addon.bridge import images, scenes
    from addon.bridge.bake import bake_file
    from addon.bridge.reference import cycles_bake
    from addon.engine import metrics
    from addon.engine.config import GIConfig, LpvConfig, RsmConfig

    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        blend = Path(tmp) / f"{args.scene}.blend"
        scenes.save(args.scene, blend)
        rsm = RsmConfig(visibility="voxel") if args.method == "rsm" else RsmConfig()
        if args.sky_rays is not None:
            rsm = replace(rsm, sky_rays=args.sky_rays)
        settings = {"gi": GIConfig(method=args.method), "rsm": rsm,
                    "lpv": LpvConfig(emitter_classes=args.emitter_classes)}
        summary = bake_file(blend, Path(tmp) / "ours", args.objects, args.size, settings, args.pass_name,
                            progress=False, supersample=args.supersample)
        bpy.ops.wm.open_mainfile(filepath=str(blend))
        cycles_pass = {args.pass_name.upper()}
        for name in args.objects:
            ours = images.read_exr(Path(tmp) / "ours" / f"{name}_{args.pass_name}.exr")
            ref, ref_s = cycles_bake(name, cycles_pass, args.ref_spp, seed=0, size=args.size)
            mask = (ref[..., 3] > 0.5) & (ours[..., 3] > 0.5)
            curve = []
            for spp in (4, 16, 64, 256):
                img, seconds = cycles_bake(name, cycles_pass, spp, seed=1, size=args.size)
                err = metrics.compare(img[..., :3], ref[..., :3], mask)
                curve.append({"spp": spp, "time_s": seconds, **err})
            err = metrics.compare(ours[..., :3], ref[..., :3], mask)
            ours_s = summary["objects"][name]["time_ms"] / 1e3
            up = metrics.cycles_equivalent_speedup(err["rel_rmse_8"], ours_s, curve)
            bound = {"=": "", "<": "<= ", ">": ">= "}.get(up["bound"], "")
            rows.append(f"| {name} | {err['rel_rmse_8']:.3f} | {err['bias']:.3f} | {ours_s * 1e3:.0f} ms "
                        f"(+ {summary['setup_ms']:.0f} ms setup per file) | "
                        + ", ".join(f"{c['spp']} spp {c['time_s']:.2f} s / {c['rel_rmse_8']:.3f}" for c in curve)
                        + f" | {bound}{up['speedup']:.2f}x |")
    classes = ", emitter classes" if args.emitter_classes and args.method == "lpv" else ""
    rays = "" if args.sky_rays is None else f", sky rays {args.sky_rays}"
    rays += "" if args.supersample == 1 else f", supersample {args.supersample}"
    print(f"{args.scene}, {args.pass_name}, method {args.method}{classes}{rays}, {args.size} x {args.size} texels; "
          f"reference: Cycles bake {args.ref_spp} spp.\n")
    print("| object | rel_rmse_8 | bias | Bounce bake | Cycles bake: spp, time / rel_rmse_8 | speed-up |")
    print("| --- | --- | --- | --- | --- | --- |")
    print("\n".join(rows))
    return 0


if __name__ == "__main__":
    sys.exit(main())
