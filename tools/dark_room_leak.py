"""Light a method puts where a path tracer puts none: its mean indirect over the covered pixels whose
Cycles reference holds no light at all (direct and indirect exactly 0: thin-wall's unlit room, which
light can reach only through the divider), over its mean indirect on the other covered pixels.

At 128 spp a lit pixel of Cycles' reference is never exactly 0, so the mask is the unlit room.

Run: .venv/bin/python tools/dark_room_leak.py --reference REF_DIR ROW_DIR [ROW_DIR ...]
  REF_DIR: a bench reference (direct.exr, indirect.exr), e.g. out/bench/refs/thin-wall-<hash>-r128-spp128-b1-seed0;
  ROW_DIR: a bench row (out/bench/runs/thin-wall/<row>) or a `render --out` directory (indirect.exr).
Prints one JSON line per row: {"row", "dark_pixels", "leak"}.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))


def leak(reference_direct: np.ndarray, reference_indirect: np.ndarray, ours: np.ndarray) -> tuple[int, float]:
    """(dark pixel count, leak). Images (h, w, 4) with alpha = coverage; rgb summed per pixel. The leak
    is 0 where the method puts nothing in the dark pixels; nan if there are no dark or no lit pixels."""
    covered = reference_indirect[..., 3] > 0
    dark = covered & (reference_indirect[..., :3].sum(-1) == 0) & (reference_direct[..., :3].sum(-1) == 0)
    lit = covered & ~dark
    light = ours[..., :3].sum(-1).astype(np.float64)
    if not dark.any() or not lit.any() or light[lit].mean() <= 0.0:
        return int(dark.sum()), float("nan")
    return int(dark.sum()), float(light[dark].mean() / light[lit].mean())


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--reference", type=Path, required=True)
    parser.add_argument("rows", type=Path, nargs="+")
    args = parser.parse_args()
    from addon.bridge import images

    direct = images.read_exr(args.reference / "direct.exr")
    indirect = images.read_exr(args.reference / "indirect.exr")
    for row in args.rows:
        count, value = leak(direct, indirect, images.read_exr(row / "indirect.exr"))
        print(json.dumps({"row": row.name, "dark_pixels": count, "leak": round(value, 5)}))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
