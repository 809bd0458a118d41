"""LPV with L2 SH against L1: a numpy twin of the improved transport (one grid, geometry volume, the
geometry-aware lookup) run on the GPU method's own VPLs, blocking volumes and G-buffer, so the only
difference between the two rows is the SH order (docs/LPV.md, "Known: lit floors read no indirect
light"). The L1 row must equal the GPU image (printed: max difference); L2 projects each VPL's cosine
lobe onto 9 coefficients, transfers with M_d = integral Y_i Y_j max(0, w.d) / |w|_1 dw (9 x 9, by
quadrature) and weights each step by the path-weight matrix integral Y_i Y_j / |w|_1 dw.

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

AXES = [(0, 1.0), (0, -1.0), (1, 1.0), (1, -1.0), (2, 1.0), (2, -1.0)]


def operators():
    """{(axis, sign): M_d (9 x 9)} and the path-weight matrix P (9 x 9), by quadrature."""
    from addon.engine import sh

    dirs, weights = sh.sphere_quadrature(512, 1024)
    inv_l1 = 1.0 / np.abs(dirs).sum(axis=1)
    basis = sh.basis_l2(dirs)
    mats = {(a, s): np.einsum("k,ki,kj->ij", np.maximum(0.0, s * dirs[:, a]) * inv_l1 * weights, basis, basis)
            for a, s in AXES}
    return mats, np.einsum("k,ki,kj->ij", inv_l1 * weights, basis, basis)


def six_bin_self_reading() -> tuple[np.ndarray, float]:
    """Six directional bins (the improved transport's sectors, weights max(0, w.d) / |w|_1, each bin's
    light spread over its sector by those weights): the shares of a floor's cosine lobe per bin, and
    what the floor reads of its own light as arriving (light travelling down), over its front reading."""
    from addon.engine import sh

    dirs, weights = sh.sphere_quadrature(512, 1024)
    sectors = [np.maximum(0.0, s * dirs[:, a]) / np.abs(dirs).sum(axis=1) for a, s in AXES]
    own = np.maximum(0.0, dirs[:, 2]) / np.pi  # the floor's Lambertian lobe, unit flux
    shares = np.array([np.sum(own * p * weights) for p in sectors])
    back = front = 0.0
    for share, p in zip(shares, sectors, strict=True):
        shape = p / np.sum(p * weights)
        back += share * np.sum(shape * np.maximum(0.0, -dirs[:, 2]) * weights)
        front += share * np.sum(shape * np.maximum(0.0, dirs[:, 2]) * weights)
    return shares, back / front


def shifted(v: np.ndarray, axis: int, sign: float) -> np.ndarray:
    """out[B] = v[B - d] for d = sign * e_axis; v is (z, y, x, ...), axis 0 = x; 0 where B - d is outside."""
    ax, out = 2 - axis, np.zeros_like(v)
    src, dst = [slice(None)] * v.ndim, [slice(None)] * v.ndim
    src[ax], dst[ax] = (slice(0, -1), slice(1, None)) if sign > 0 else (slice(1, None), slice(0, -1))
    out[tuple(dst)] = v[tuple(src)]
    return out


def propagate(s0, k, mats, path, through, steps):
    """Accumulated snapshots 1..steps (the injection is not accumulated), each weighted by `path`."""
    acc, cur = np.zeros_like(s0), s0
    for _ in range(steps):
        nxt = np.zeros_like(cur)
        for d in AXES:
            nxt += through[d][..., None] * (shifted(cur, *d) @ mats[d][:k, :k].T)
        cur = nxt
        acc += cur @ path[:k, :k].T
    return acc


def lookup(acc, grid, vox_normal, pos, nrm, band2):
    """lookup.comp.glsl's geometry-aware trilinear read at pos + h/2 n, E / pi, any SH order."""
    from addon.engine import sh

    k, h, dims = acc.shape[-1], grid.cell_size_m, np.array(grid.dims)
    g = (pos + 0.5 * h * nrm - grid.origin_m) / h - 0.5
    i0 = np.floor(g).astype(int)
    f = g - i0
    lobe = sh.cosine_lobe_l1(-nrm) if k == 4 else sh.cosine_lobe_l2(-nrm) * np.r_[np.ones(4), np.full(5, band2)]
    aware, plain, w_aware = np.zeros((len(pos), k)), np.zeros((len(pos), k)), np.zeros(len(pos))
    for corner in np.ndindex(2, 2, 2):
        c = np.array(corner)
        idx = np.clip(i0 + c, 0, dims - 1)
        w = np.prod(np.where(c == 1, f, 1 - f), axis=1)
        vn = vox_normal[idx[:, 2], idx[:, 1], idx[:, 0]]
        through = 1.0 - np.minimum(1.0, vn[:, 3] * np.abs(np.sum(vn[:, :3] * nrm, axis=1)))
        v = acc[idx[:, 2], idx[:, 1], idx[:, 0]]
        plain += w[:, None] * v
        aware += (w * through)[:, None] * v
        w_aware += w * through
    s = np.where((w_aware > 1e-4)[:, None], aware / np.maximum(w_aware, 1e-4)[:, None], plain)
    return np.maximum(np.sum(s * lobe, axis=1), 0.0) / (h * h * np.pi)


def run_scene(name, src, args, mats, path):
    import bpy

    from addon.bridge import bench, images
    from addon.bridge.capture import SceneCache, define_light_switch, image_size
    from addon.bridge.pipeline import backend, open_blend
    from addon.engine import metrics, sh
    from addon.engine.config import GIConfig, LpvConfig, RsmConfig
    from addon.engine.methods.lpv import LpvMethod, iterations_for

    cache = Path("out/bench")
    blend = bench._cache_blend(name, src, cache)
    ref_dir, _ = bench._reference(blend, f"{name}-{bench._sha(blend)}", args.spp, 1, args.res, 0, cache)
    ref = images.read_exr(ref_dir / "indirect.exr")
    mask = ref[..., 3] > 0.5
    open_blend(blend)
    define_light_switch()
    width, height = image_size(bpy.context.scene, args.res)
    be = backend()
    method = LpvMethod(be, GIConfig(method="lpv", resolution=args.res), RsmConfig(), LpvConfig(far_field=False))
    method.set_scene(SceneCache().update(bpy.context.evaluated_depsgraph_get(), width, height))
    vpls, per_light_view = [], method.per_light_view

    def keep_vpls(view, timings):  # the VPLs the GPU injection used (after the RSM reduction)
        per_light_view(view, timings)
        rsm = method._vpls if method._vpls is not None else method.rsm
        p, n, phi = (be.read(rsm[key]).astype(np.float64) for key in ("position", "normal", "flux"))
        ok = p[..., 3] != 0
        vpls.append((p[ok][:, :3], n[ok][:, :3], phi[ok][:, :3]))

    method.per_light_view = keep_vpls
    gpu = method.run().images["indirect"]
    grid, level = method.grid, method.levels[0]
    h, dims = grid.cell_size_m, np.array(grid.dims)
    pos, nrm, flux = (np.concatenate([v[i] for v in vpls]) for i in range(3))
    nrm /= np.maximum(np.linalg.norm(nrm, axis=1, keepdims=True), 1e-12)
    cell = np.floor((pos + 0.6 * h * nrm - grid.origin_m) / h).astype(int)  # inject.vert.glsl's cell
    inside = np.all((cell >= 0) & (cell < dims), axis=1)
    cell, flux, lobes = cell[inside], flux[inside], sh.cosine_lobe_l2(nrm[inside]) / np.pi
    plus, minus = (be.read(level.blocking[k])[..., :3].astype(np.float64) for k in ("block_plus", "block_minus"))
    through = {}
    for a, s in AXES:  # propagate.comp.glsl: 1 - (A's share leaving along d) - (B's share entering)
        leave = shifted((plus if s > 0 else minus)[..., a], a, s)
        through[(a, s)] = np.maximum(0.0, 1.0 - leave - (minus if s > 0 else plus)[..., a])
    gpos, gnrm = be.read(method.gbuf["position"]), be.read(method.gbuf["normal"])
    valid = gpos[..., 3] != 0
    ppos, pn = gpos[valid][:, :3].astype(np.float64), gnrm[valid][:, :3].astype(np.float64)
    pn /= np.maximum(np.linalg.norm(pn, axis=1, keepdims=True), 1e-12)
    vox_normal = be.read(level.voxels["vox_normal"]).astype(np.float64)
    steps = iterations_for(method.lpv_config, grid)
    row = {"gpu": metrics.compare(gpu, ref, mask)}
    for k in (4, 9):
        img = np.zeros(gpu.shape, np.float32)  # G-buffer order: row 0 = bottom
        for ch in range(3):
            s0 = np.zeros((dims[2], dims[1], dims[0], k))
            np.add.at(s0, (cell[:, 2], cell[:, 1], cell[:, 0]), flux[:, ch:ch + 1] * lobes[:, :k])
            acc = propagate(s0, k, mats, path if k == 9 else np.eye(4) * path[0, 0], through, steps)
            img[..., ch][valid] = lookup(acc, grid, vox_normal, ppos, pn, args.band2)
        img = np.ascontiguousarray(img[::-1])
        img[..., 3] = gpu[..., 3]
        row[k] = metrics.compare(img, ref, mask)
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
    mats, path = operators()
    found, skipped = bench.resolve_scenes(args.scenes.split(","), bench.Options().shared_scenes)
    print(f"rel_rmse_8 / bias vs Cycles ({args.spp} spp, {args.res} px), one 32-cell grid, band-2 lookup x "
          f"{args.band2}\n\n| scene | GPU (L1) | numpy L1 (max diff to GPU) | numpy L2 |\n| --- | --- | --- | --- |")
    for name, src in found:
        r = run_scene(name, src, args, mats, path)
        print(f"| {name} | {r['gpu']['rel_rmse_8']:.3f} / {r['gpu']['bias']:.2f} | {r[4]['rel_rmse_8']:.3f} / "
              f"{r[4]['bias']:.2f} ({r['l1_vs_gpu']:.1e}) | {r[9]['rel_rmse_8']:.3f} / {r[9]['bias']:.2f} |",
              flush=True)
    for name, why in skipped.items():
        print(f"| {name} | skipped: {why} | | |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
