"""`python -m addon compare A.exr B.exr`: errors of A against the reference B, as one JSON object.

If B has an alpha channel it is the reference's geometry mask (alpha > 0.5 counts, as written by
`reference`), less the pixels whose albedo.exr beside B or beside A is black (an emitter's panel, where
Cycles' Diffuse passes are 0): the pixels `bench` judges (reference.reference_mask). A plain RGB reference
counts every pixel. Images of different sizes: exit 2. HDR-FLIP is
added when the flip-evaluator package is installed (requirements.txt pins it), else reported as null.
Only linear float images are compared (OpenEXR, Radiance HDR): a PNG, JPEG or TIFF holds display-encoded
integers (sRGB), whose errors mean something else; they exit 2.
"""

from __future__ import annotations

import json

from ..bridge import images
from ..bridge.reference import reference_mask
from ..engine.errors import BackendUnavailable, ConfigError
from ..engine.metrics import compare, hdr_flip

NAME = "compare"
HELP = "print rel_rmse, rel_rmse_8, bias, HDR-FLIP of A.exr against the reference B.exr as JSON"


def add_arguments(parser) -> None:
    parser.add_argument("test", metavar="A.exr", help="image under test")
    parser.add_argument("reference", metavar="B.exr", help="reference (its alpha, if any, is the mask)")


# OpenImageIO's names of the formats that hold scene-linear floats.
LINEAR_FORMATS = ("openexr", "hdr")


def _file_format(path) -> tuple[str, str]:
    """OpenImageIO's format name and pixel type of a readable image file (read_exr has opened it)."""
    import OpenImageIO as oiio

    inp = oiio.ImageInput.open(str(path))
    try:
        return inp.format_name(), str(inp.spec().format)
    finally:
        inp.close()


def check_linear(path) -> None:
    """Refuse an image whose file format is not linear float (ConfigError: exit 2, one line)."""
    name, pixel_type = _file_format(path)
    if name not in LINEAR_FORMATS:
        raise ConfigError(f"{path}: a {name} file ({pixel_type} pixels) is not linear float, as PNG, JPEG and "
                          "TIFF are taken to be display-encoded: compare linear EXR images (or .hdr)")


def compare_files(test_path, reference_path) -> dict:
    a = images.read_exr(test_path)
    b = images.read_exr(reference_path)
    check_linear(test_path)
    check_linear(reference_path)
    if a.shape[:2] != b.shape[:2]:
        raise ConfigError(f"images differ in size: {test_path} is {a.shape[1]}x{a.shape[0]}, "
                          f"{reference_path} is {b.shape[1]}x{b.shape[0]}")
    if a.shape[2] < 3 or b.shape[2] < 3:
        raise ConfigError("compare needs RGB or RGBA images")
    mask = reference_mask(reference_path, b, test_path)
    masked = mask is not None
    try:
        flip = hdr_flip(a[:, :, :3], b[:, :, :3], mask)
    except BackendUnavailable:
        flip = None
    return {**compare(a[:, :, :3], b[:, :, :3], mask), "hdr_flip": flip, "masked": masked}


def run(args) -> int:
    print(json.dumps(compare_files(args.test, args.reference)))
    return 0
