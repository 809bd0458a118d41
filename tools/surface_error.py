"""Where a method's indirect light is wrong, by surface: the pixels grouped by the dominant signed axis of
their normal (a room's floor, ceiling and walls), optionally split into height bands, each group's bias
against a Cycles reference and its share of the image's squared error.

    .venv/bin/python tools/surface_error.py BLEND --reference REF/indirect.exr --method diffusion \
        [--bands 4] [--set diffusion.grid_cells=16 ...]

The reference must be of the same scene and camera (bench's references are); the image is rendered at the
reference's size. bias = mean(ours) /
mean(Cycles) over the group's pixels (luminance as the mean of r, g, b); share = the group's sum of
squared differences over the whole image's; the line of all covered pixels also gives the image's
rel_rmse_8 (the benchmark's error, addon/engine/metrics.py). A group below 1 % of the covered pixels is
not printed. Prints one JSON line per group.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "tools"))

from noise_table import build_settings, parse_sets  # noqa: E402

AXES = ("+x", "-x", "+y", "-y", "+z", "-z")


def groups(position: np.ndarray, normal: np.ndarray, bands: int) -> dict[str, np.ndarray]:
    """Masks of covered pixels by the normal's dominant signed axis, each split into `bands` equal bands
    of world height (z) over the covered pixels' range."""
    covered = position[..., 3] > 0
    n = normal[..., :3]
    axis = np.abs(n).argmax(axis=-1)
    negative = np.take_along_axis(n, axis[..., None], axis=-1)[..., 0] < 0
    label = 2 * axis + negative
    z = position[..., 2]
    lo, hi = z[covered].min(), z[covered].max()
    band = np.clip(((z - lo) / max(hi - lo, 1e-9) * bands).astype(int), 0, bands - 1)
    out = {}
    step_m = (hi - lo) / bands
    for k, name in enumerate(AXES):
        for b in range(bands):
            key = name if bands == 1 else f"{name} z {lo + b * step_m:.2f}..{lo + (b + 1) * step_m:.2f}"
            out[key] = covered & (label == k) & (band == b)
    return out


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("blend")
    parser.add_argument("--reference", required=True)
    parser.add_argument("--method", required=True)
    parser.add_argument("--bands", type=int, default=1)
    parser.add_argument("--set", dest="sets", action="append", default=[], help="group.name=value")
    args = parser.parse_args()
    import bpy

    from addon.bridge import images, pipeline
    from addon.bridge.capture import SceneCache
    from addon.engine import methods, metrics

    reference_rgb = images.read_exr(args.reference)[..., :3].astype(np.float64)
    height, width = reference_rgb.shape[:2]
    bpy.ops.wm.open_mainfile(filepath=str(Path(args.blend).resolve()))
    scene = SceneCache().update(bpy.context.evaluated_depsgraph_get(), width, height)
    be = pipeline.backend()
    method = methods.create(be, build_settings(args.method, max(width, height), parse_sets(args.sets)))
    method.set_scene(scene)
    ours_rgb = method.run().images["indirect"][..., :3].astype(np.float64)
    ours, reference = ours_rgb.mean(axis=-1), reference_rgb.mean(axis=-1)
    # The G-buffer is read with GL's row 0 at the bottom; the method's image has row 0 at the top.
    position, normal = (be.read(method.gbuf[k])[::-1] for k in ("position", "normal"))
    squared = (ours - reference) ** 2
    covered = position[..., 3] > 0
    total = squared[covered].sum()
    print(json.dumps({"group": "all", "pixels": int(covered.sum()),
                      "bias": round(ours[covered].mean() / reference[covered].mean(), 3), "share": 1.0,
                      "rel_rmse_8": round(metrics.rel_rmse_8(ours_rgb, reference_rgb), 3)}))
    for name, mask in groups(position, normal, args.bands).items():
        if mask.sum() < 0.01 * covered.sum():
            continue
        print(json.dumps({"group": name, "pixels": int(mask.sum()),
                          "bias": round(ours[mask].mean() / reference[mask].mean(), 3),
                          "share": round(squared[mask].sum() / total, 3) if total > 0 else 0.0}))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
