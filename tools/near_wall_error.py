"""The error of methods' indirect light at receivers near walls: the pixels whose surface point lies within
a share of the room's size of a second side of the scene's bounds (a crease or a corner of a room), against
a Cycles reference of the same scene, camera and size (docs/GATHER.md, "Measured").

    .venv/bin/python tools/near_wall_error.py SCENE.blend REFERENCE_DIR [--res 128] [--share 0.02 0.05]
        [--methods gather,gather:point,probes]

REFERENCE_DIR holds `indirect.exr` (and, when present, a second seed's `../<name with seed1>/indirect.exr`
is reported as the reference's own noise). Per method: bias = mean(ours) / mean(Cycles) over those pixels,
rel_rmse = sqrt(mean((ours - Cycles)^2)) / mean(Cycles) (per pixel: the region is a few pixels wide, so no
box averaging), and the brightest pixel over Cycles' brightest there. Only the bounds' six planes count
as walls (objects inside a room do not). `gather:point` is gather with the point-to-point form factor.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))


def near_wall_mask(position: np.ndarray, lo: np.ndarray, hi: np.ndarray, distance_m: float) -> np.ndarray:
    """Pixels with geometry whose point is within `distance_m` of a second plane of the bounds (the first
    being the one it lies on, for a room's surfaces)."""
    p = position[..., :3].astype(np.float64)
    d = np.sort(np.concatenate([p - lo, hi - p], axis=-1), axis=-1)
    return (position[..., 3] > 0) & (d[..., 1] < distance_m)


def errors(ours: np.ndarray, reference: np.ndarray, mask: np.ndarray) -> dict:
    a, b = ours[..., :3][mask].astype(np.float64), reference[..., :3][mask].astype(np.float64)
    return {"bias": a.mean() / b.mean(), "rel_rmse": float(np.sqrt(((a - b) ** 2).mean()) / b.mean()),
            "max_ratio": float(a.max() / b.max())}


def main(argv: list[str]) -> int:
    parser = argparse.ArgumentParser(description=__doc__.strip().splitlines()[0])
    parser.add_argument("blend")
    parser.add_argument("reference")
    parser.add_argument("--res", type=int, default=128)
    parser.add_argument("--share", type=float, nargs="+", default=[0.02, 0.05])
    parser.add_argument("--methods", default="gather,gather:point,probes")
    args = parser.parse_args(argv)
    import bpy

    from addon.bridge import images
    from addon.bridge.capture import SceneCache
    from addon.engine import methods
    from addon.engine.backends.moderngl_backend import ModernGLBackend
    from addon.engine.config import GatherConfig, GIConfig

    be = ModernGLBackend()
    bpy.ops.wm.open_mainfile(filepath=str(Path(args.blend).resolve()))
    scene = SceneCache().update(bpy.context.evaluated_depsgraph_get(), args.res, args.res)
    ref_dir = Path(args.reference)
    reference = images.read_exr(ref_dir / "indirect.exr")
    rows = {}
    second = ref_dir.with_name(ref_dir.name.replace("seed0", "seed1"))
    if second != ref_dir and (second / "indirect.exr").exists():
        rows["Cycles, seed 1"] = images.read_exr(second / "indirect.exr")
    position = bounds = None
    for name in args.methods.split(","):
        method_name, _, variant = name.partition(":")
        extra = {"gather": GatherConfig(form_factor=variant)} if variant else {}
        method = methods.create(be, {"gi": GIConfig(method=method_name, resolution=args.res), **extra})
        method.set_scene(scene)
        rows[name] = method.run().images["indirect"]
        position, bounds = be.read(method.gbuf["position"])[::-1], method.bounds_m
    lo, hi = (np.asarray(b, np.float64) for b in bounds)
    for share in args.share:
        mask = near_wall_mask(position, lo, hi, share * float((hi - lo).max()))
        print(f"within {share:g} x the room's size of a second wall: {int(mask.sum())} pixels")
        for name, image in rows.items():
            e = errors(image, reference, mask)
            print(f"  {name:16s} bias {e['bias']:.3f}  rel_rmse {e['rel_rmse']:.3f}  brightest {e['max_ratio']:.2f}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
