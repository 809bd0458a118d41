"""`python -m addon compare A.exr B.exr`: errors of A against the reference B, as one JSON object.

If B has an alpha channel it is the reference's geometry mask (alpha > 0.5 counts, as written by
`reference`); a plain RGB reference counts every pixel. Images of different sizes: exit 2. HDR-FLIP is
added when the flip-evaluator package is installed (requirements.txt pins it), else reported as null.
"""

from __future__ import annotations

import json

from ..bridge import images
from ..engine.errors import BackendUnavailable, ConfigError
from ..engine.metrics import compare, hdr_flip

NAME = "compare"
HELP = "print rel_rmse, rel_rmse_8, bias, HDR-FLIP of A.exr against the reference B.exr as JSON"


def add_arguments(parser) -> None:
    parser.add_argument("test", metavar="A.exr", help="image under test")
    parser.add_argument("reference", metavar="B.exr", help="reference (its alpha, if any, is the mask)")


def compare_files(test_path, reference_path) -> dict:
    a = images.read_exr(test_path)
    b = images.read_exr(reference_path)
    if a.shape[:2] != b.shape[:2]:
        raise ConfigError(f"images differ in size: {test_path} is {a.shape[1]}x{a.shape[0]}, "
                          f"{reference_path} is {b.shape[1]}x{b.shape[0]}")
    if a.shape[2] < 3 or b.shape[2] < 3:
        raise ConfigError("compare needs RGB or RGBA images")
    masked = b.shape[2] >= 4
    mask = b[:, :, 3] > 0.5 if masked else None
    try:
        flip = hdr_flip(a[:, :, :3], b[:, :, :3], mask)
    except BackendUnavailable:
        flip = None
    return {**compare(a[:, :, :3], b[:, :, :3], mask), "hdr_flip": flip, "masked": masked}


def run(args) -> int:
    print(json.dumps(compare_files(args.test, args.reference)))
    return 0
