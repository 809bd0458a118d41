"""What the denoise pass (addon/engine/passes/denoise.py) costs next to a vct update, and what it does to
vct's per-pixel noise.

    .venv/bin/python tools/denoise_cost.py out/cornell.blend --res 128 512 [--iterations 2 3]
        [--references DIR]

Per resolution: the median wall time (GPU work finished) of a vct update (`updates.update_costs`' lights update,
as `render --profile-updates` reports it: no read-back, no per-pass waits) and, per iteration count, of
the filter run on that update's `indirect`, and their ratio (the target is <= 20 %). With --references,
DIR/<res>/indirect.exr (`python -m addon reference BLEND --res <res> --out DIR/<res>`) is the Cycles
reference: the indirect's rel_rmse and rel_rmse_8 before and after the filter are printed too. Prints
one JSON line per resolution.
"""

from __future__ import annotations

import argparse
import json
import statistics
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from addon.engine import metrics  # noqa: E402
from addon.engine.passes import denoise  # noqa: E402
from addon.engine.updates import update_costs  # noqa: E402


def filter_ms(method, out, scratch, guide, params: denoise.Params, repeat: int) -> float:
    """Median wall time (ms) of the filter on the method's indirect, GPU work finished."""
    be = method.backend
    noisy = method.product_textures()["indirect"]
    samples = []
    for _ in range(repeat + 1):  # the first run compiles the program
        be.finish()
        t0 = time.perf_counter()
        denoise.run(be, method.gbuf, noisy, out, scratch, params, guide=guide)
        be.finish()
        samples.append((time.perf_counter() - t0) * 1e3)
    return statistics.median(samples[1:])


def errors(image, reference) -> dict:
    """rel_rmse and rel_rmse_8 of an (h, w, 4) image (row 0 = top) against a Cycles reference, over the
    reference's geometry mask."""
    found = metrics.compare(image[..., :3], reference[..., :3], reference[..., 3] > 0.5)
    return {key: found[key] for key in ("rel_rmse", "rel_rmse_8")}


def measure(blend: Path, res: int, iterations: list[int], repeat: int, references: Path | None) -> dict:
    import bpy

    from addon.bridge import images, pipeline
    from addon.bridge.capture import SceneCache, image_size
    from addon.engine import methods
    from addon.engine.config import GIConfig, settings

    pipeline.open_blend(blend)
    width, height = image_size(bpy.context.scene, res)
    scene = SceneCache().update(bpy.context.evaluated_depsgraph_get(), width, height)
    be = pipeline.backend()
    method = methods.create(be, settings(gi=GIConfig(method="vct", resolution=res)))
    method.set_scene(scene)
    before = method.run().images["indirect"]  # also the warm-up
    update_ms = update_costs(method, repeat, kinds=("lights",))["lights"]  # the solve and gathers, no upload
    out, scratch, guide = (be.texture((width, height)) for _ in range(3))
    reference = images.read_exr(references / str(res) / "indirect.exr") if references is not None else None
    row = {"res": res, "vct_update_ms": update_ms}
    if reference is not None:
        row["unfiltered"] = errors(before, reference)
    for k in iterations:
        ms = filter_ms(method, out, scratch, guide, denoise.Params(iterations=k), repeat)
        row[f"iterations_{k}"] = found = {"filter_ms": ms, "ratio": ms / update_ms}
        if reference is not None:
            found.update(errors(be.read(out)[::-1], reference))  # read-back rows: 0 = bottom
    return row


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("blend", type=Path)
    parser.add_argument("--res", type=int, nargs="+", default=[128, 512])
    parser.add_argument("--iterations", type=int, nargs="+",
                        help="iteration counts to time (default: denoise.iterations_for(res))")
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--references", type=Path, help="DIR with <res>/indirect.exr Cycles references")
    args = parser.parse_args()
    for res in args.res:
        iterations = args.iterations or [denoise.iterations_for(res)]
        print(json.dumps(measure(args.blend, res, iterations, args.repeat, args.references)), flush=True)


if __name__ == "__main__":
    main()
