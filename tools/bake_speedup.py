"""Bounce's bake against Cycles' bake curve: texel-space error vs time, and the Cycles-equivalent
speed-up (time Cycles' bake needs to reach our rel_rmse_8 / our bake time), on the Cornell box.

    .venv/bin/python tools/bake_speedup.py [--size 64] [--method rsm|lpv|vct] [--emitter-classes] > table.md

Reference: a Cycles bake at --ref-spp (seed 0); Cycles' curve: bakes at increasing spp with seed 1;
Bounce: --method (rsm with voxel visibility by default; lpv and vct at their defaults), per object
(setup = capture, upload and voxelization, once per file, reported apart). Prints a Markdown table for
benchmarks/REPORT.md.
"""

from __future__ import annotations

import argparse
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

OBJECTS = ("Floor", "BackWall")


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--size", type=int, default=64)
    ap.add_argument("--ref-spp", type=int, default=1024)
    from addon.engine import registry

    indirect = [m.name for m in registry.METHODS if "indirect" in m.products]
    ap.add_argument("--method", default="rsm", choices=indirect)
    ap.add_argument("--emitter-classes", action="store_true", help="lpv: LpvConfig.emitter_classes")
    args = ap.parse_args()

    import bpy

    from addon.bridge import images, scenes
    from addon.bridge.bake import bake_file
    from addon.bridge.reference import cycles_bake
    from addon.engine import metrics
    from addon.engine.config import GIConfig, LpvConfig, RsmConfig

    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        blend = Path(tmp) / "cornell.blend"
        scenes.save("cornell", blend)
        rsm = RsmConfig(visibility="voxel") if args.method == "rsm" else RsmConfig()
        settings = {"gi": GIConfig(method=args.method), "rsm": rsm,
                    "lpv": LpvConfig(emitter_classes=args.emitter_classes)}
        summary = bake_file(blend, Path(tmp) / "ours", list(OBJECTS), args.size, settings, "indirect", progress=False)
        bpy.ops.wm.open_mainfile(filepath=str(blend))
        for name in OBJECTS:
            ours = images.read_exr(Path(tmp) / "ours" / f"{name}_indirect.exr")
            ref, ref_s = cycles_bake(name, {"INDIRECT"}, args.ref_spp, seed=0, size=args.size)
            mask = (ref[..., 3] > 0.5) & (ours[..., 3] > 0.5)
            curve = []
            for spp in (4, 16, 64, 256):
                img, seconds = cycles_bake(name, {"INDIRECT"}, spp, seed=1, size=args.size)
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
    print(f"Cornell box, indirect, method {args.method}{classes}, {args.size} x {args.size} texels; reference: "
          f"Cycles bake {args.ref_spp} spp.\n")
    print("| object | rel_rmse_8 | bias | Bounce bake | Cycles bake: spp, time / rel_rmse_8 | speed-up |")
    print("| --- | --- | --- | --- | --- | --- |")
    print("\n".join(rows))
    return 0


if __name__ == "__main__":
    sys.exit(main())
