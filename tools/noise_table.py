"""Noise, error and filter cost of the stochastic methods (issue #22's table), in one process.

    .venv/bin/python tools/noise_table.py BLEND --reference REF/indirect.exr --res 128 \
        --methods rsm,vct [--accumulate 1 16] [--set vct.diffuse_cones=24 ...] [--cost]

Per method and accumulate count N: the indirect of two renders that differ only in GIConfig.seed (0 and
1), each averaging N gathers (`render --accumulate N`: run, then N - 1 refines), as the CLI writes it.
noise = rel_rmse of seed 1's image against seed 0's; rel_rmse / rel_rmse_8 / bias = seed 0's against
the Cycles reference (metrics.compare over the reference's geometry mask); `raw` the same for the
unfiltered gather (GIConfig.denoise off), which shows the grain the filter had to remove. With --cost,
the median time of the denoise pass on one product (all its iterations) over the median time of a
lights update (updates.update_costs; the solve and the gathers, filter included). Prints one JSON line
per method.
"""

from __future__ import annotations

import argparse
import json
import statistics
import sys
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from addon.engine import metrics  # noqa: E402


def parse_sets(items: list[str]) -> dict[str, dict[str, str]]:
    """['vct.diffuse_cones=24'] -> {'vct': {'diffuse_cones': '24'}}."""
    out: dict[str, dict[str, str]] = {}
    for item in items:
        key, _, value = item.partition("=")
        group, _, name = key.partition(".")
        if not value or not name:
            raise SystemExit(f"--set takes group.name=value, not {item!r}")
        out.setdefault(group, {})[name] = value
    return out


def build_settings(method: str, res: int, sets: dict[str, dict[str, str]], **gi) -> dict:
    """Every group's config: defaults, `sets` (converted to each field's type), then GIConfig's `gi`."""
    import dataclasses

    from addon.engine.config import GROUPS, GIConfig, settings

    configs = {}
    for group, values in sets.items():
        cls = GROUPS[group]
        types = {f.name: type(f.default) for f in dataclasses.fields(cls)}
        configs[group] = cls(**{k: (v.lower() in ("1", "true", "on")) if types[k] is bool else types[k](v)
                                for k, v in values.items()})
    base = configs.pop("gi", GIConfig())
    configs["gi"] = replace(base, method=method, resolution=res, **gi)
    return settings(**configs)


def indirect(method, samples: int):
    """The indirect after one update and samples - 1 refinements (row 0 = top)."""
    method.run()
    for _ in range(samples - 1):
        method.refine()
    return method.read()["indirect"]


def errors(image, reference) -> dict:
    found = metrics.compare(image[..., :3], reference[..., :3], reference[..., 3] > 0.5)
    return {k: round(found[k], 4) for k in ("rel_rmse", "rel_rmse_8", "bias")}


def filter_share(method, repeat: int) -> dict:
    """Median ms of the denoise pass on the indirect and of a lights update, and their ratio."""
    from addon.engine.passes import denoise
    from addon.engine.updates import update_costs

    be = method.backend
    update_ms = update_costs(method, repeat, kinds=("lights",))["lights"]
    size = method.gbuf["position"].size
    noisy, out, scratch, guide = (be.texture(size) for _ in range(4))
    params = denoise.Params(iterations=denoise.iterations_for(max(size)))
    samples = []
    for _ in range(repeat + 1):  # the first run compiles the program
        be.finish()
        t0 = time.perf_counter()
        denoise.run(be, method.gbuf, noisy, out, scratch, params, guide=guide)
        be.finish()
        samples.append((time.perf_counter() - t0) * 1e3)
    filter_ms = statistics.median(samples[1:])
    return {"update_ms": round(update_ms, 1), "filter_ms": round(filter_ms, 2),
            "filter_share": round(filter_ms / update_ms, 3)}


def pair_noise(images: list, mask) -> tuple[float, list[float]]:
    """rel_rmse between the images of seeds 2j and 2j + 1, per pair, and its root mean square over the
    pairs: one pair's figure moves with the two seeds' draws (by ~20 % on cornell's vct), so the mean of
    several estimates the noise more closely."""
    pairs = [metrics.rel_rmse(images[j + 1][..., :3], images[j][..., :3], mask) for j in range(0, len(images), 2)]
    return float(np.sqrt(np.mean(np.square(pairs)))), pairs


def measure(scene, name: str, res: int, sets, accumulate: list[int], reference, cost: bool, repeat: int,
            seed_pairs: int = 1) -> dict:
    from addon.bridge import pipeline
    from addon.engine import methods

    be = pipeline.backend()
    row: dict = {"method": name, "res": res, "set": sets}
    mask = reference[..., 3] > 0.5
    for n in accumulate:
        images = []
        for seed in range(2 * seed_pairs):
            method = methods.create(be, build_settings(name, res, sets, seed=seed))
            method.set_scene(scene)
            images.append(indirect(method, n))
        noise, pairs = pair_noise(images, mask)
        row[f"n{n}"] = {"noise": round(noise, 4), **errors(images[0], reference)}
        if seed_pairs > 1:
            row[f"n{n}"]["noise_pairs"] = [round(x, 4) for x in pairs]
    raw = []
    for seed in (0, 1):
        method = methods.create(be, build_settings(name, res, sets, seed=seed, denoise=False))
        method.set_scene(scene)
        raw.append(indirect(method, 1))
    row["raw"] = {"noise": round(metrics.rel_rmse(raw[1][..., :3], raw[0][..., :3], reference[..., 3] > 0.5), 4),
                  **errors(raw[0], reference)}
    if cost:
        method = methods.create(be, build_settings(name, res, sets))
        method.set_scene(scene)
        method.run()
        row.update(filter_share(method, repeat))
    return row


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("blend", type=Path)
    parser.add_argument("--reference", type=Path, required=True, help="Cycles indirect.exr at --res")
    parser.add_argument("--res", type=int, default=128)
    parser.add_argument("--methods", default="rsm,vct")
    parser.add_argument("--accumulate", type=int, nargs="+", default=[1, 16])
    parser.add_argument("--set", dest="sets", action="append", default=[], help="group.name=value")
    parser.add_argument("--cost", action="store_true", help="time the filter against a lights update")
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--seed-pairs", type=int, default=1,
                        help="noise as the root mean square over seed pairs (0, 1), (2, 3), ...")
    args = parser.parse_args()

    import bpy

    from addon.bridge import images, pipeline
    from addon.bridge.capture import SceneCache, image_size

    pipeline.open_blend(args.blend)
    width, height = image_size(bpy.context.scene, args.res)
    scene = SceneCache().update(bpy.context.evaluated_depsgraph_get(), width, height)
    reference = images.read_exr(args.reference)
    sets = parse_sets(args.sets)
    for name in args.methods.split(","):
        print(json.dumps(measure(scene, name, args.res, sets, args.accumulate, reference, args.cost,
                                 args.repeat, args.seed_pairs)), flush=True)


if __name__ == "__main__":
    main()
