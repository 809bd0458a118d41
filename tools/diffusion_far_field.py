"""diffusion's far field against one grid: error against Cycles and a lights update's time, in one process.

    .venv/bin/python tools/diffusion_far_field.py SCENE.blend=REF_DIR [...] [--res 128] [--bounces 1] \
        [--rounds 5]

Per scene (REF_DIR/indirect.exr: `python -m addon reference SCENE.blend --res R --bounces B --out REF_DIR`),
three `diffusion` settings at their defaults otherwise: the far field off (every step on the one grid),
on with its default near steps (half the bounce's steps), and on with a quarter of them. rel_rmse_8 and
bias against the reference (metrics.compare over the reference's geometry mask); a lights update's
median time over `rounds`, the three methods timed in turn (updates.update_costs_in_turn: a shared
machine's drift falls alike on all three), and each one's time over the one grid's. Prints a markdown
table, one row per scene (docs/DIFFUSION.md, "Far field").
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "tools"))

from noise_table import build_settings, errors  # noqa: E402

# (label, DiffusionConfig overrides as --set values); "quarter" is filled in per scene from its steps.
SETTINGS = (("one grid", {"far_field": "false"}), ("far field", {}), ("far field, K / 2", None))


def measure(blend: Path, reference_dir: Path, res: int, bounces: int, rounds: int) -> list[str]:
    import bpy

    from addon.bridge import images, pipeline
    from addon.bridge.capture import SceneCache, image_size
    from addon.engine import methods
    from addon.engine.methods.diffusion import steps_per_bounce
    from addon.engine.passes import diffusion_far_field
    from addon.engine.updates import update_costs_in_turn

    pipeline.open_blend(blend)
    width, height = image_size(bpy.context.scene, res)
    scene = SceneCache().update(bpy.context.evaluated_depsgraph_get(), width, height)
    reference = images.read_exr(reference_dir / "indirect.exr")
    be = pipeline.backend()
    made, cells = [], []
    for _, values in SETTINGS:
        if values is None:  # a quarter of the bounce's steps: half the default near steps
            m = made[1]
            steps = steps_per_bounce(m.diffusion_config, m.grid, bounces)
            values = {"near_steps": str(diffusion_far_field.near_steps(0, steps) // 2)}
        m = methods.create(be, build_settings("diffusion", res, {"diffusion": values}, bounces=bounces))
        m.set_scene(scene)
        found = errors(_indirect(m), reference)
        made.append(m)
        cells.append(found)
    times = [costs["lights"] for costs in update_costs_in_turn(made, rounds)]
    row = [blend.stem]
    for found, ms in zip(cells, times, strict=True):
        row.append(f"{found['rel_rmse_8']:.3f} / {found['bias']:.3f}, {ms:.0f} ms ({ms / times[0]:.2f}x)")
    return row


def _indirect(method):
    method.run()
    return method.read()["indirect"]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scenes", nargs="+", help="SCENE.blend=REF_DIR")
    parser.add_argument("--res", type=int, default=128)
    parser.add_argument("--bounces", type=int, default=1)
    parser.add_argument("--rounds", type=int, default=5)
    args = parser.parse_args()
    print("| scene | " + " | ".join(label for label, _ in SETTINGS) + " |")
    print("| --- |" + " --- |" * len(SETTINGS))
    for item in args.scenes:
        blend, _, ref = item.partition("=")
        if not ref:
            raise SystemExit(f"expected SCENE.blend=REF_DIR, not {item!r}")
        row = measure(Path(blend), Path(ref), args.res, args.bounces, args.rounds)
        print("| " + " | ".join(row) + " |", flush=True)


if __name__ == "__main__":
    main()
