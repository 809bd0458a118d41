"""The brightest pixels of an indirect image against a reference's: the spike check of method `gather`
(docs/GATHER.md, "Measured").

    .venv/bin/python tools/brightest_pixels.py OURS.exr REFERENCE.exr [--share 0.01]

Over the pixels where the reference has geometry (its alpha > 0), each image's own brightest `share`
of pixels by the mean of their RGB: prints JSON with the mean of ours over the mean of the reference's
(`ratio`; spikes make it large, a missing highlight small) and the largest pixel of each. Both images
are read whole; nothing is box-averaged, since a spike is a few pixels wide.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))


def brightest_mean(image: np.ndarray, mask: np.ndarray, share: float) -> float:
    """The mean of the brightest `share` of the masked pixels (at least one), by the mean of RGB."""
    values = np.sort(image[..., :3].mean(axis=-1)[mask])[::-1]
    return float(values[:max(1, int(round(share * values.size)))].mean())


def compare(ours: np.ndarray, reference: np.ndarray, share: float = 0.01) -> dict:
    mask = reference[..., 3] > 0 if reference.shape[-1] == 4 else np.ones(reference.shape[:2], bool)
    a, b = brightest_mean(ours, mask, share), brightest_mean(reference, mask, share)
    return {"share": share, "ratio": a / b, "ours_mean": a, "reference_mean": b,
            "ours_max": float(ours[..., :3][mask].max()), "reference_max": float(reference[..., :3][mask].max())}


def main(argv: list[str]) -> int:
    parser = argparse.ArgumentParser(description=__doc__.strip().splitlines()[0])
    parser.add_argument("ours")
    parser.add_argument("reference")
    parser.add_argument("--share", type=float, default=0.01)
    args = parser.parse_args(argv)
    from addon.bridge import images

    print(json.dumps(compare(images.read_exr(args.ours), images.read_exr(args.reference), args.share)))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
