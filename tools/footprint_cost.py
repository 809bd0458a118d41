"""What drawing each light view at its footprint's texels (light_views.view_texels) saves, and what it
changes, against every perspective view at RsmConfig.resolution.

    .venv/bin/python tools/footprint_cost.py BLEND [BLEND ...] [--res 128] [--methods rsm,lpv,...]
        [--rounds 5]

Per scene and method (its defaults at --res px): the texels the light views draw under each rule, the
median wall time (GPU work finished) of a lights update (`updates.update_costs`: the light views, the
solve and the gathers, the G-buffer kept), the two timed in turn over --rounds rounds so that the
machine's drift falls alike on both, their ratio, and how far the footprint rule moves the indirect
light (mean |difference| over the full-texel image's mean). The full-texel rule is view_texels
replaced by one that returns its `most`. Prints one JSON line per scene and method.
"""

from __future__ import annotations

import argparse
import json
import statistics
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from addon.engine.passes import light_views  # noqa: E402
from addon.engine.updates import update_costs  # noqa: E402

FOOTPRINT = light_views.view_texels


def every_texel(footprint_m: float, texel_m: float, most: int) -> int:
    """The rule before footprints: every perspective view at the resolution."""
    return most


def measure(blend: Path, res: int, names: list[str], rounds: int) -> list[dict]:
    import bpy

    from addon.bridge import pipeline
    from addon.bridge.capture import SceneCache, image_size
    from addon.engine import methods
    from addon.engine.config import GIConfig, settings

    pipeline.open_blend(blend)
    width, height = image_size(bpy.context.scene, res)
    scene = SceneCache().update(bpy.context.evaluated_depsgraph_get(), width, height)
    be = pipeline.backend()
    rows = []
    for name in names:
        found = {}
        for rule in (FOOTPRINT, every_texel):
            light_views.view_texels = rule
            method = methods.create(be, settings(gi=GIConfig(method=name, resolution=res)))
            method.set_scene(scene)
            image = method.run().images["indirect"]  # also the warm-up
            texels = sum(v.resolution ** 2 for v in method.light_views())
            found[rule.__name__] = {"method": method, "image": image, "texels": texels, "ms": []}
        for _ in range(rounds):
            for rule in (FOOTPRINT, every_texel):
                light_views.view_texels = rule
                run = found[rule.__name__]
                run["ms"].append(update_costs(run["method"], 1, kinds=("lights",))["lights"])
        light_views.view_texels = FOOTPRINT
        ours, full = found[FOOTPRINT.__name__], found[every_texel.__name__]
        a, b = ours["image"][..., :3], full["image"][..., :3]
        rows.append({
            "scene": blend.stem, "method": name, "res": res, "texels": ours["texels"],
            "texels_every": full["texels"], "texel_share": ours["texels"] / full["texels"],
            "lights_update_ms": statistics.median(ours["ms"]), "lights_update_ms_every": statistics.median(full["ms"]),
            "time_ratio": statistics.median(ours["ms"]) / statistics.median(full["ms"]),
            "indirect_change": float(np.abs(a - b).mean() / max(float(np.abs(b).mean()), 1e-30))})
    return rows


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("blends", type=Path, nargs="+")
    parser.add_argument("--res", type=int, default=128)
    # the methods whose solve reads every RSM texel (probes and gather spend their updates elsewhere)
    parser.add_argument("--methods", default="rsm,lpv,vct,diffusion")
    parser.add_argument("--rounds", type=int, default=5)
    args = parser.parse_args()
    for blend in args.blends:
        for row in measure(blend, args.res, args.methods.split(","), args.rounds):
            print(json.dumps(row), flush=True)


if __name__ == "__main__":
    main()
