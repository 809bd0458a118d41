"""LPV with L2 SH against L1: the numpy twin of the improved transport (addon/engine/lpv_reference.py;
one grid, geometry volume, the geometry-aware lookup) run on the GPU method's own VPLs, blocking volumes
and G-buffer, so the only difference between the two rows is the SH order (docs/LPV.md, "Known: lit
floors read no indirect light"). The L1 row must equal the GPU image (printed: max difference); L2
projects each VPL's cosine lobe onto 9 coefficients, transfers with M_d = integral Y_i Y_j max(0, w.d) /
|w|_1 dw (9 x 9, by quadrature) and weights each step by the path-weight matrix integral Y_i Y_j / |w|_1
dw.

    .venv/bin/python tools/lpv_sh_order.py [--scenes cornell,window-room] [--band2 1.0]

Scenes and Cycles references come from the bench's cache (out/bench; made if missing: 512 spp, 128 px,
one bounce). --band2 scales the lookup's band-2 lobe (1: the clamped cosine). It first prints what a
lit floor would read of its own light with six directional bins instead (`six_bin_self_reading`). A
research tool: slow (numpy), not part of the method.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

QUADRATURE_THETA = 512  # the transfer's and path weight's quadrature, both orders


def operators() -> dict[int, tuple]:
    """{k: (M_d for lpv_reference.AXES, path-weight matrix)} for k = 4 and 9 coefficients. The L1 row
    takes the L1 block of the L2 transfer (the same quadrature) and, as the GPU, one path weight for
    all four coefficients, so the rows differ only in the SH order."""
    from addon.engine import lpv_reference as ref

    mats = ref.transfer_matrices("improved", order=2, n_theta=QUADRATURE_THETA)
    path = ref.path_weight(2, QUADRATURE_THETA)
    return {4: (tuple(m[:4, :4] for m in mats), np.eye(4) * path[0, 0]), 9: (mats, path)}


def six_bin_self_reading() -> tuple[np.ndarray, float]:
    """Six directional bins (the improved transport's sectors, weights max(0, w.d) / |w|_1, each bin's
    light spread over its sector by those weights): the shares of a floor's cosine lobe per bin, and
    what the floor reads of its own light as arriving (light travelling down), over its front reading."""
    from addon.engine import sh
    from addon.engine.lpv_reference import AXES

    dirs, weights = sh.sphere_quadrature(QUADRATURE_THETA, 2 * QUADRATURE_THETA)
    sectors = [np.maximum(0.0, s * dirs[:, a]) / np.abs(dirs).sum(axis=1) for a, s in AXES]
    own = np.maximum(0.0, dirs[:, 2]) / np.pi  # the floor's Lambertian lobe, unit flux
    shares = np.array([np.sum(own * p * weights) for p in sectors])
    back = front = 0.0
    for share, p in zip(shares, sectors, strict=True):
        shape = p / np.sum(p * weights)
        back += share * np.sum(shape * np.maximum(0.0, -dirs[:, 2]) * weights)
        front += share * np.sum(shape * np.maximum(0.0, dirs[:, 2]) * weights)
    return shares, back / front


def run_scene(name, src, args, ops):
    import bpy

    from addon.bridge import bench, images
    from addon.bridge.capture import SceneCache, define_light_switch, image_size
    from addon.bridge.pipeline import backend, open_blend
    from addon.engine import lpv_reference as ref
    from addon.engine import metrics
    from addon.engine.config import GIConfig, LpvConfig, RsmConfig
    from addon.engine.methods.lpv import LpvMethod, iterations_for

    cache = Path("out/bench")
    blend = bench._cache_blend(name, src, cache)
    ref_dir, _ = bench._reference(blend, f"{name}-{bench._sha(blend)}", args.spp, 1, args.res, 0, cache)
    ref_image = images.read_exr(ref_dir / "indirect.exr")
    mask = ref_image[..., 3] > 0.5
    open_blend(blend)
    define_light_switch()
    width, height = image_size(bpy.context.scene, args.res)
    be = backend()
    method = LpvMethod(be, GIConfig(method="lpv", resolution=args.res), RsmConfig(), LpvConfig(far_field=False))
    method.set_scene(SceneCache().update(bpy.context.evaluated_depsgraph_get(), width, height))
    vpls, solve_view = [], method.solve_view

    def keep_vpls(view, timings):  # the VPLs the GPU injection used (after the RSM reduction)
        solve_view(view, timings)
        rsm = method._vpls if method._vpls is not None else method.rsm
        p, n, phi = (be.read(rsm[key]).astype(np.float64) for key in ("position", "normal", "flux"))
        ok = p[..., 3] != 0
        vpls.append((p[ok][:, :3], n[ok][:, :3], phi[ok][:, :3]))

    method.solve_view = keep_vpls
    gpu = method.run().images["indirect"]
    grid, level = method.grid, method.levels[0]
    pos, nrm, flux = (np.concatenate([v[i] for v in vpls]) for i in range(3))
    nrm /= np.maximum(np.linalg.norm(nrm, axis=1, keepdims=True), 1e-12)
    plus, minus = (be.read(level.blocking[k])[..., :3].astype(np.float64) for k in ("block_plus", "block_minus"))
    through = ref.pass_through(plus, minus)  # the GPU's own blocking volumes
    gpos, gnrm = be.read(method.gbuf["position"]), be.read(method.gbuf["normal"])
    valid = gpos[..., 3] != 0
    ppos, pn = gpos[valid][:, :3].astype(np.float64), gnrm[valid][:, :3].astype(np.float64)
    pn /= np.maximum(np.linalg.norm(pn, axis=1, keepdims=True), 1e-12)
    vox_normal = be.read(level.voxels["vox_normal"]).astype(np.float64)
    steps = iterations_for(method.lpv_config, grid)
    row = {"gpu": metrics.compare(gpu, ref_image, mask)}
    for k, (mats, path) in ops.items():
        img = np.zeros(gpu.shape, np.float32)  # G-buffer order: row 0 = bottom
        for ch in range(3):
            s0 = ref.inject(grid, pos, nrm, flux[:, ch], order=1 if k == 4 else 2)
            acc = ref.accumulate(s0, mats, path, steps, through)
            img[..., ch][valid] = ref.lookup(acc, grid, ppos, pn, vox_normal, band2_scale=args.band2)
        img = np.ascontiguousarray(img[::-1])
        img[..., 3] = gpu[..., 3]
        row[k] = metrics.compare(img, ref_image, mask)
        if k == 4:
            row["l1_vs_gpu"] = float(np.abs(img[..., :3] - gpu[..., :3]).max() / max(gpu[..., :3].max(), 1e-30))
    return row


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scenes", default="cornell,window-room,thin-wall,sponza,sibenik,conference")
    ap.add_argument("--res", type=int, default=128)
    ap.add_argument("--spp", type=int, default=512)
    ap.add_argument("--band2", type=float, default=1.0)
    args = ap.parse_args()

    from addon.bridge import bench

    shares, ratio = six_bin_self_reading()
    print(f"six directional bins: a floor's cosine lobe per bin (+x -x +y -y +z -z) {np.round(shares, 3)}; it "
          f"reads {ratio:.1%} of its own front reading as arriving\n")
    ops = operators()
    found, skipped = bench.resolve_scenes(args.scenes.split(","), bench.Options().shared_scenes)
    print(f"rel_rmse_8 / bias vs Cycles ({args.spp} spp, {args.res} px), one 32-cell grid, band-2 lookup x "
          f"{args.band2}\n\n| scene | GPU (L1) | numpy L1 (max diff to GPU) | numpy L2 |\n| --- | --- | --- | --- |")
    for name, src in found:
        r = run_scene(name, src, args, ops)
        print(f"| {name} | {r['gpu']['rel_rmse_8']:.3f} / {r['gpu']['bias']:.2f} | {r[4]['rel_rmse_8']:.3f} / "
              f"{r[4]['bias']:.2f} ({r['l1_vs_gpu']:.1e}) | {r[9]['rel_rmse_8']:.3f} / {r[9]['bias']:.2f} |",
              flush=True)
    for name, why in skipped.items():
        print(f"| {name} | skipped: {why} | | |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
