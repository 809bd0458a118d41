"""EXR input/output with OpenImageIO only (no bpy), so references can be read outside Blender.

OpenImageIO is imported on first use, not with this module: Blender builds need not have it (Debian's
has none) and the extension does not ship it, so the paths a user runs inside Blender (the overlay, the
bake operator's packed images) never import it; the CLI's venv installs it from requirements.txt. The
Cycles renders Bounce makes inside Blender are written uncompressed and read without it (read_multilayer,
exr.py).

Arrays are float32 (h, w, c) with row 0 = the TOP of the image (EXR order; GL read-backs must be
flipped before writing). Channels are R, G, B[, A]. Pixels are written as 32-bit FLOAT: half floats
lose ~3 decimal digits, which is more than the noise floor we want to measure.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..engine.errors import BackendUnavailable, SceneError

_CHANNELS = {3: ("R", "G", "B"), 4: ("R", "G", "B", "A")}


def _oiio():
    try:
        import OpenImageIO
    except ImportError:
        raise BackendUnavailable("reading or writing EXR files needs the OpenImageIO module, which this Python "
                                 "lacks: run the command line from the project's venv (make test sets it up)") from None
    return OpenImageIO


def write_exr(path, pixels) -> None:
    """Write float32 (h, w, 3|4) pixels, row 0 = top, as a single-part FLOAT EXR."""
    px = np.ascontiguousarray(pixels, dtype=np.float32)
    if px.ndim != 3 or px.shape[2] not in _CHANNELS:
        raise ValueError(f"write_exr wants (h, w, 3|4) pixels, got shape {px.shape}")
    h, w, c = px.shape
    oiio = _oiio()
    spec = oiio.ImageSpec(w, h, c, oiio.FLOAT)
    spec.channelnames = _CHANNELS[c]
    if c == 4:
        spec.alpha_channel = 3
    spec.attribute("compression", "zip")  # lossless
    out = oiio.ImageOutput.create(str(path))
    if out is None or not out.open(str(path), spec):
        raise SceneError(f"cannot write {path}: {oiio.geterror() or (out and out.geterror())}")
    try:
        if not out.write_image(px):
            raise SceneError(f"cannot write {path}: {out.geterror()}")
    finally:
        out.close()


def _open(path):
    """An OpenImageIO ImageInput."""
    if not Path(path).is_file():
        raise SceneError(f"no such image: {path}")
    oiio = _oiio()
    inp = oiio.ImageInput.open(str(path))
    if inp is None:
        raise SceneError(f"cannot read image {path}: {oiio.geterror()}")
    return inp


def _read_subimage(inp, sub: int, path) -> tuple[np.ndarray, list[str]]:
    """Pixels and channel names of one subimage. Name the subimage explicitly: in OIIO 3.0 the
    short read_image(chbegin, chend, format) form leaves inp.spec() pointing at subimage 0."""
    if not inp.seek_subimage(sub, 0):
        raise SceneError(f"cannot read image {path}: no subimage {sub}")
    spec = inp.spec()
    names = list(spec.channelnames)
    px = inp.read_image(sub, 0, 0, spec.nchannels, _oiio().FLOAT)
    if px is None:
        raise SceneError(f"cannot read image {path}: {inp.geterror()}")
    return np.asarray(px, dtype=np.float32).reshape(spec.height, spec.width, spec.nchannels), names


def read_exr(path) -> np.ndarray:
    """The first subimage of an image file as float32 (h, w, c), row 0 = top."""
    inp = _open(path)
    try:
        return _read_subimage(inp, 0, path)[0]
    finally:
        inp.close()


def read_multilayer(path) -> dict[str, np.ndarray]:
    """An uncompressed multi-layer EXR from Blender as {pass name: float32 (h, w, c)}, read without
    OpenImageIO (exr.py), so it works inside any Blender: Bounce writes its own renders so
    (compat.multilayer_exr, codec NONE).

    Blender 5.0 writes each pass as its own part with channels "<view layer>.<pass>.<chan>", e.g.
    "ViewLayer.Diffuse Indirect.R"; Combined is "ViewLayer.Combined.R/G/B/A". 4.x puts all passes in
    one part. See passes_by_name for the keys and the channels' order.
    """
    from . import exr

    if not Path(path).is_file():
        raise SceneError(f"no such image: {path}")
    return passes_by_name(exr.read_parts(path), path)


# Blender before 5.0 names the passes in a multi-layer EXR by their short names; 5.0 by the long ones
# used everywhere else (docs/ARCHITECTURE.md, Blender versions).
_LONG_PASS_NAMES = {"DiffDir": "Diffuse Direct", "DiffInd": "Diffuse Indirect", "DiffCol": "Diffuse Color",
                    "GlossDir": "Glossy Direct", "GlossInd": "Glossy Indirect", "GlossCol": "Glossy Color"}

# A pass's channels in the order its consumers index them (colour R, G, B, A; vectors X, Y, Z, W), as
# OpenImageIO returns them; the file itself lists them alphabetically.
_CHANNEL_RANK = {"R": 0, "G": 1, "B": 2, "A": 3, "X": 0, "Y": 1, "Z": 2, "W": 3}


def passes_by_name(parts: list[tuple[list[str], np.ndarray]], path) -> dict[str, np.ndarray]:
    """{pass name: float32 (h, w, c)} from an EXR's parts ((channel names, pixels) each). Channels are
    "<layer>.<pass>.<chan>" (pass names contain no dots in Blender), "<pass>.<chan>", or bare (Combined);
    passes are named as Blender 5.0 names them (_LONG_PASS_NAMES) and their channels go in _CHANNEL_RANK's
    order. Only the first view layer found is kept under the bare pass name; others (rare in our scenes)
    are keyed "<layer>.<pass>"."""
    passes: dict[str, np.ndarray] = {}
    first_layer = None
    for names, px in parts:
        groups: dict[str, list[tuple[int, str]]] = {}
        for i, name in enumerate(names):
            fields = name.split(".")
            if len(fields) >= 3:
                layer, pname = fields[0], ".".join(fields[1:-1])
            elif len(fields) == 2:
                layer, pname = "", fields[0]
            else:
                layer, pname = "", "Combined"
            pname = _LONG_PASS_NAMES.get(pname, pname)
            first_layer = layer if first_layer is None else first_layer
            key = pname if layer == first_layer else f"{layer}.{pname}"
            groups.setdefault(key, []).append((i, fields[-1]))
        for key, channels in groups.items():
            ordered = sorted(channels, key=lambda c: (_CHANNEL_RANK.get(c[1], 4), c[1]))
            passes[key] = np.ascontiguousarray(px[:, :, [i for i, _ in ordered]])
    if not passes:
        raise SceneError(f"no passes in {path}")
    return passes
