"""`python -m addon demo --out out/demo`: build the Cornell box, render direct and indirect light with
Bounce and with Cycles, and write images and a short report. Everything shown is computed."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..engine import metrics
from ..engine.config import GIConfig, RsmConfig
from ._args import add_quiet, output_dir, progress
from ._settings import add_field_flag

NAME = "demo"
HELP = "build the demo Cornell box, render it with Bounce and with Cycles, write images and a report"


def add_arguments(p) -> None:
    p.add_argument("--out", default="out/demo", help="output directory")
    add_field_flag(p, GIConfig, "resolution", "--res", default=128, doc="long side of the images in pixels")
    p.add_argument("--spp", type=int, default=64, help="Cycles samples per pixel for the comparison")
    add_quiet(p)


def _png(path: Path, linear_rgb: np.ndarray) -> None:
    """sRGB-encoded PNG of linear radiance (clipped at 1): a plain view, no tone curve to hide errors."""
    import matplotlib.pyplot as plt

    c = np.clip(linear_rgb, 0.0, 1.0)
    srgb = np.where(c <= 0.0031308, 12.92 * c, 1.055 * np.power(c, 1 / 2.4) - 0.055)
    plt.imsave(path, srgb)


def run(args) -> int:
    from ..bridge.reference import check_settings

    check_settings(args.spp, 1, args.res)
    out = output_dir(args.out)
    from ..bridge import images, scenes
    from ..bridge.pipeline import render_file
    from ..bridge.reference import render_reference

    say = progress(args.quiet)
    blend = out / "cornell.blend"
    say(f"building the Cornell box -> {blend}")
    scenes.save("cornell", blend)
    say("rendering direct and indirect light with Bounce (method rsm, voxel visibility; moderngl)")
    stats = render_file(blend, out, {"gi": GIConfig(method="rsm", resolution=args.res),
                                     "rsm": RsmConfig(visibility="voxel")}, progress=say)
    say(f"rendering the same with Cycles ({args.spp} spp) for comparison")
    ref_dir = out / "cycles"
    ref = render_reference(blend, ref_dir, spp=args.spp, bounces=1, res=args.res, seed=0, progress=say)

    albedo = images.read_exr(out / "albedo.exr")
    mask = images.read_exr(ref_dir / "direct.exr")[..., 3] > 0.5
    light, rows = {}, []
    for product in ("direct", "indirect"):
        ours = images.read_exr(out / f"{product}.exr")[..., :3]
        cyc = images.read_exr(ref_dir / f"{product}.exr")[..., :3]
        light[product] = (ours, cyc)
        e = metrics.compare(ours, cyc, mask)
        rows.append(f"| {product} | {e['rel_rmse']:.3f} | {e['rel_rmse_8']:.3f} | {e['bias']:.3f} |")
    _png(out / "bounce.png", albedo[..., :3] * (light["direct"][0] + light["indirect"][0]))
    _png(out / "cycles.png", albedo[..., :3] * (light["direct"][1] + light["indirect"][1]))

    report = out / "report.md"
    report.write_text(
        "# Bounce demo\n\n"
        f"Scene: the Cornell box (`python -m addon scene cornell`), {stats['image_size'][0]} x "
        f"{stats['image_size'][1]} px, {stats['triangles']} triangles, one 300 W spot, one diffuse bounce.\n\n"
        "| image | what |\n| --- | --- |\n"
        "| bounce.png | Bounce `rsm` (voxel visibility): (direct + indirect) x albedo |\n"
        f"| cycles.png | Cycles (Diffuse Direct + Diffuse Indirect) x albedo, {args.spp} spp |\n\n"
        f"Bounce full update: {stats['total_ms']:.1f} ms (median of {stats['runs']} after a warm-up) on "
        f"{stats['renderer']}; Cycles: {ref['render_time_s']:.2f} s on {ref['device']}.\n\n"
        "Error against Cycles (Cycles' own noise at this sample count is part of it):\n\n"
        "| pass | rel_rmse | rel_rmse_8 | bias |\n| --- | --- | --- | --- |\n" + "\n".join(rows) + "\n"
    )
    print(f"wrote {out}/bounce.png, cycles.png, *.exr and {report}")
    return 0
