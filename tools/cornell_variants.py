"""Two variants of the `cornell` benchmark scene that take its boxes' part in the indirect light apart
(docs/DIFFUSION.md, "Small bright patches"): `cornell-no-boxes` (the room and the spot alone),
`cornell-black-boxes` (the boxes kept, albedo 0: they shadow and absorb but reflect nothing, so the
ceiling's indirect light is the floor's and the walls') and `cornell-black-floor` (the floor's albedo
0: the ceiling's is the boxes' and the walls'). Reference them as any scene (`python -m addon
reference`); on a black surface Cycles' Diffuse Indirect pass reads 0 (it is the light over the
surface's colour, 0 where the colour is), so compare the other surfaces.

    .venv/bin/python tools/cornell_variants.py OUT_DIR   (writes OUT_DIR/<variant>.blend)
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

BOXES = ("ShortBox", "TallBox")


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("out_dir")
    args = parser.parse_args()
    import bpy

    from addon.bridge import scenes

    out = Path(args.out_dir)
    out.mkdir(parents=True, exist_ok=True)
    scenes.build("cornell")
    for name in BOXES:
        bpy.data.objects.remove(bpy.data.objects[name])
    bpy.ops.wm.save_as_mainfile(filepath=str(out / "cornell-no-boxes.blend"), check_existing=False)
    for variant, objects in (("cornell-black-boxes", BOXES), ("cornell-black-floor", ("Floor",))):
        scenes.build("cornell")
        black = scenes._material("Black", (0.0, 0.0, 0.0))
        for name in objects:
            mesh = bpy.data.objects[name].data
            mesh.materials.clear()
            mesh.materials.append(black)
        bpy.ops.wm.save_as_mainfile(filepath=str(out / f"{variant}.blend"), check_existing=False)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
