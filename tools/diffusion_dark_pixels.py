"""Where `diffusion` leaves lit surfaces dark, and how much of its error that is: the pixels that read
under a tenth of Cycles' indirect where Cycles' is above its 30th percentile over the covered pixels,
their share of the reference's light, the error with and without them, and what the cells they read hold.

    .venv/bin/python tools/diffusion_dark_pixels.py BLEND --reference REF/indirect.exr \
        [--set diffusion.grid_cells=64 ...]

The reference must be of the same scene and camera (bench's references are); the image is rendered at
the reference's size. Prints one JSON object:
- grid: cells per axis, cell_m (edge, m), occupied (share of the cells holding a surface);
- dark: pixels, ref_light_share (their share of the reference's summed luminance), reading_lit (how
  many read at least one cell whose side facing them receives light: lit cells, but too little light);
- alignment: the mean over the dark pixels and over the others of the best |n . n_cell| among the
  receiving cells a pixel reads (1: the cell's one plane is the pixel's surface);
- brighter_side: over the dark pixels, the mean of the reconstruction (diffusion_reference.lookup on the
  GPU's cells and fluxes) with every cell giving its brighter side, over Cycles' mean: near 1, the light
  is in the cells they read but on the side of the plane that faces away from them;
- rel_rmse_8 (the image), rel_rmse_8_without_dark (the dark pixels replaced by the reference), bias_others
  (mean over the other covered pixels against Cycles').
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

from addon.engine import diffusion_reference  # noqa: E402

DARK_RATIO = 0.1        # a pixel below this share of Cycles' value reads as unlit
LIT_PERCENTILE = 30.0   # ... where Cycles' value is above this percentile of the covered pixels'
RECEIVES_PLUS, RECEIVES_MINUS = 64, 128  # diffusion/cell.glsl's bits of cell_block.w - 1


def dark_mask(lum: np.ndarray, ref_lum: np.ndarray, covered: np.ndarray) -> np.ndarray:
    """Covered pixels reading under DARK_RATIO of the reference where the reference is above its
    LIT_PERCENTILE over the covered pixels."""
    lit = ref_lum > np.percentile(ref_lum[covered], LIT_PERCENTILE)
    return covered & lit & (lum < DARK_RATIO * ref_lum)


def best_alignment(points_m, normals, grid, block, plane) -> np.ndarray:
    """Per point, the largest |n . n_cell| over the 8 cells the lookup reads (diffusion/lookup.comp.glsl)
    that hold a surface whose side facing n receives light; 0 where none does."""
    best = np.zeros(len(points_m))
    points_cells = (points_m - np.asarray(grid.origin_m)) / grid.cell_size_m
    for cc, _, inside in diffusion_reference.lookup_corners(points_cells, grid.dims):
        b = block[cc[:, 2], cc[:, 1], cc[:, 0]]
        n_cell = plane[cc[:, 2], cc[:, 1], cc[:, 0], :3]
        dn = np.sum(normals * n_cell, axis=1)
        mask = np.maximum(b[:, 3], 1.0).astype(int) - 1
        receives = (mask & np.where(dn >= 0, RECEIVES_PLUS, RECEIVES_MINUS)) != 0
        ok = inside & (b[:, 3] > 0) & receives
        best = np.where(ok, np.maximum(best, np.abs(dn)), best)
    return best


def parse_args(description: str) -> argparse.Namespace:
    """BLEND --reference REF/indirect.exr [--set group.name=value ...]: the diffusion tools' arguments."""
    parser = argparse.ArgumentParser(description=description)
    parser.add_argument("blend")
    parser.add_argument("--reference", required=True)
    parser.add_argument("--set", dest="sets", action="append", default=[], help="group.name=value")
    return parser.parse_args()


def diffusion_at_reference(blend: str, reference_path: str, sets: list[str]):
    """(backend, the diffusion method set to the scene at the reference's size with `sets`, the
    reference's rgb in float64)."""
    import bpy

    from addon.bridge import images, pipeline
    from addon.bridge.capture import SceneCache
    from addon.engine import methods

    reference = images.read_exr(reference_path)[..., :3].astype(np.float64)
    height, width = reference.shape[:2]
    bpy.ops.wm.open_mainfile(filepath=str(Path(blend).resolve()))
    scene = SceneCache().update(bpy.context.evaluated_depsgraph_get(), width, height)
    be = pipeline.backend()
    method = methods.create(be, build_settings("diffusion", max(width, height), parse_sets(sets)))
    method.set_scene(scene)
    return be, method, reference


def main() -> int:
    args = parse_args(__doc__.splitlines()[0])
    from addon.engine import metrics

    be, method, reference = diffusion_at_reference(args.blend, args.reference, args.sets)
    ours = method.run().images["indirect"][..., :3].astype(np.float64)
    # The G-buffer is read with GL's row 0 at the bottom; the method's image has row 0 at the top.
    position, normal = (be.read(method.gbuf[k])[::-1] for k in ("position", "normal"))
    covered = position[..., 3] > 0
    lum, ref_lum = ours.mean(axis=-1), reference.mean(axis=-1)
    dark = dark_mask(lum, ref_lum, covered)
    others = covered & ~dark

    grid, block, plane = method.grid, be.read(method.cells["cell_block"]), be.read(method.cells["cell_normal"])
    n = normal[..., :3] / np.maximum(np.linalg.norm(normal[..., :3], axis=-1, keepdims=True), 1e-12)
    align = {k: best_alignment(position[m][:, :3], n[m], grid, block, plane) for k, m in (("dark", dark),
                                                                                          ("others", others))}
    flux = {k: be.read(method.accumulated[k])[..., :3].mean(axis=-1).astype(np.float64)
            for k in ("flux_plus", "flux_minus")}
    brighter = np.maximum(flux["flux_plus"], flux["flux_minus"])
    occupied = block[..., 3] > 0
    cells = {"occupied": occupied, "normal": plane[..., :3].astype(np.float64), "area": plane[..., 3],
             "receives": np.stack([occupied, occupied], axis=-1)}
    points_cells = (position[dark][:, :3] - np.asarray(grid.origin_m)) / grid.cell_size_m
    either_side = diffusion_reference.lookup(points_cells, n[dark], cells, brighter, brighter,
                                             grid.cell_size_m ** 2)
    filled = ours.copy()
    filled[dark] = reference[dark]
    print(json.dumps({
        "grid": {"cells": list(grid.dims), "cell_m": round(grid.cell_size_m, 3),
                 "occupied": round(float((block[..., 3] > 0).mean()), 3)},
        "dark": {"pixels": int(dark.sum()), "ref_light_share": round(float(ref_lum[dark].sum()
                                                                           / ref_lum[covered].sum()), 3),
                 "reading_lit": int((align["dark"] > 0).sum())},
        "alignment": {k: round(float(v.mean()), 3) if len(v) else None for k, v in align.items()},
        "brighter_side": round(float(either_side.mean() / ref_lum[dark].mean()), 3) if dark.any() else None,
        "rel_rmse_8": round(metrics.rel_rmse_8(ours, reference), 3),
        "rel_rmse_8_without_dark": round(metrics.rel_rmse_8(filled, reference), 3),
        "bias_others": round(float(lum[others].mean() / ref_lum[others].mean()), 3),
    }))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
