"""How each method's full update grows with the image's pixels: the per-pixel share the choice model
(addon/engine/choice.py) scales its predicted times by.

    .venv/bin/python tools/pixel_scaling.py BLEND [BLEND ...] [--res 128,256] [--methods rsm,lpv,...]
        [--rounds 5] [--out benchmarks/choice/pixel_scaling.json]

The choice bench times every row at one resolution (128 px on the long side), so its rows cannot tell
how a method's time grows with the image: a slope fitted on the few pixel counts the scenes' aspects
give (16 384 down to 8 192) extrapolated to a viewport's million pixels by factors of 10^4. Here each
method at its defaults runs the update the bench times (Method.run: G-buffer, light views, solve,
gathers, read-back; the setup passes of set_scene are outside it) at the two resolutions of --res, the
runs of every method and resolution timed in turn over --rounds rounds (so the machine's drift falls
alike on all), and the update is split as t(P) = t_fixed + t_pixel P through the medians at P_low and
P_high pixels (each part at least 0: timing noise can make the line's slope or intercept negative). The
per-pixel share is stated at choice.TIME_REFERENCE_PIXELS, P_ref: s = t_pixel P_ref / (t_fixed + t_pixel
P_ref). Per method the output keeps the mean of s over the scenes (`per_pixel_share`), which
tools/fit_choice.py gives choice.fit.
"""

from __future__ import annotations

import argparse
import json
import platform
import statistics
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from addon.engine.choice import TIME_REFERENCE_PIXELS  # noqa: E402

METHODS = "rsm,lpv,vct,probes,diffusion,gather"


def per_pixel_share(ms_low: float, ms_high: float, pixels_low: int, pixels_high: int,
                    reference_pixels: int = TIME_REFERENCE_PIXELS) -> float:
    """The share of the update at `reference_pixels` that grows with the pixels, from t(P) = t_fixed +
    t_pixel P through the two medians, each part clamped at 0."""
    ms_per_pixel = max((ms_high - ms_low) / (pixels_high - pixels_low), 0.0)
    fixed_ms = max(ms_low - ms_per_pixel * pixels_low, 0.0)
    grows = ms_per_pixel * reference_pixels
    return grows / (fixed_ms + grows) if grows > 0 else 0.0


def measure(blend: Path, resolutions: tuple[int, int], names: list[str], rounds: int) -> list[dict]:
    import bpy

    from addon.bridge import pipeline
    from addon.bridge.capture import SceneCache, image_size
    from addon.engine import methods
    from addon.engine.config import GIConfig, settings

    pipeline.open_blend(blend)
    be = pipeline.backend()
    runs = {}
    for res in resolutions:
        width, height = image_size(bpy.context.scene, res)
        scene = SceneCache().update(bpy.context.evaluated_depsgraph_get(), width, height)
        for name in names:
            method = methods.create(be, settings(gi=GIConfig(method=name, resolution=res)))
            method.set_scene(scene)
            method.run()  # the warm-up: shaders compiled, textures made
            runs[name, res] = {"method": method, "pixels": width * height, "ms": []}
    for _ in range(rounds):
        for run in runs.values():
            run["ms"].append(run["method"].run().timings_ms["total"])
    low, high = resolutions
    rows = []
    for name in names:
        a, b = runs[name, low], runs[name, high]
        ms_low, ms_high = statistics.median(a["ms"]), statistics.median(b["ms"])
        rows.append({"scene": blend.stem, "method": name, "res": [low, high], "pixels": [a["pixels"], b["pixels"]],
                     "update_ms": [ms_low, ms_high],
                     "per_pixel_share": per_pixel_share(ms_low, ms_high, a["pixels"], b["pixels"])})
    return rows


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("blends", type=Path, nargs="+")
    parser.add_argument("--res", default="128,256", help="the two long sides, in pixels")
    parser.add_argument("--methods", default=METHODS)
    parser.add_argument("--rounds", type=int, default=5)
    parser.add_argument("--out", type=Path, help="write the rows and the per-method shares here as JSON")
    args = parser.parse_args(argv)
    low, high = (int(r) for r in args.res.split(","))
    if not low < high:
        raise SystemExit("--res: give the lower long side first, then a higher one")
    names = args.methods.split(",")
    rows = []
    for blend in args.blends:
        for row in measure(blend, (low, high), names, args.rounds):
            print(json.dumps(row), flush=True)
            rows.append(row)
    shares = {name: statistics.mean(r["per_pixel_share"] for r in rows if r["method"] == name) for name in names}
    print(json.dumps({"per_pixel_share": shares}))
    if args.out:
        command = " ".join(["tools/pixel_scaling.py", *(str(b) for b in args.blends), "--res", args.res,
                            "--methods", args.methods, "--rounds", str(args.rounds)])
        args.out.parent.mkdir(parents=True, exist_ok=True)
        args.out.write_text(json.dumps({"command": f".venv/bin/python {command}", "machine": platform.platform(),
                                        "rows": rows, "per_pixel_share": shares}, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
