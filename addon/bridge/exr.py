"""Uncompressed OpenEXR scanline files read with numpy alone: the passes of Bounce's own Cycles renders
inside any Blender.

Why: images.py reads EXR through OpenImageIO, which the command line's venv has but a Blender build need
not (Debian's has none), and Python cannot read a multi-layer Render Result's passes from memory. The
renders that Bounce makes inside Blender (reference.render_open: the choice's check, references, the
EEVEE anchor) are written with compression NONE, whose layout is simple enough to read here:

    magic 20000630, version 2 with flags (0x1000: multi-part; tiled and deep files are refused)
    header(s): attributes (name NUL, type NUL, int32 size, value), each header ending in a NUL byte;
               a multi-part file's header list ends in one more NUL
    an offset table per part: uint64 file offset of each chunk (one scanline a chunk without compression)
    chunks: [int32 part number, multi-part only] int32 y, int32 byte count, then each channel's
            width samples in turn, channels in the header's (alphabetical) order

(the OpenEXR file layout document, "Technical Introduction" and "OpenEXR File Layout"). All little-endian.
"""

from __future__ import annotations

import struct
from pathlib import Path

import numpy as np

from ..engine.errors import SceneError

MAGIC = 20000630
_TILED, _LONG_NAMES, _DEEP, _MULTIPART = 0x200, 0x400, 0x800, 0x1000
_SAMPLE_TYPES = {0: np.dtype("<u4"), 1: np.dtype("<f2"), 2: np.dtype("<f4")}  # UINT, HALF, FLOAT
_NO_COMPRESSION = 0


def read_parts(path) -> list[tuple[list[str], np.ndarray]]:
    """Each part of an uncompressed scanline EXR as (channel names in the file's order, float32 pixels
    (h, w, channels), row 0 = the top). SceneError for anything else (compressed, tiled, deep,
    subsampled channels, or not an EXR)."""
    data = Path(path).read_bytes()
    if len(data) < 8 or struct.unpack_from("<i", data, 0)[0] != MAGIC:
        raise SceneError(f"{path}: not an OpenEXR file")
    version = struct.unpack_from("<i", data, 4)[0]
    if version & (_TILED | _DEEP):
        raise SceneError(f"{path}: a tiled or deep EXR (only scanline images are read here)")
    multipart = bool(version & _MULTIPART)
    pos, headers = 8, []
    while True:
        header, pos = _header(data, pos, path)
        headers.append(header)
        if not multipart:
            break
        if data[pos] == 0:  # the empty header that ends a multi-part file's list
            pos += 1
            break
    tables = []
    for header in headers:
        rows = header["dataWindow"][3] - header["dataWindow"][1] + 1
        tables.append(np.frombuffer(data, "<u8", rows, pos))
        pos += 8 * rows
    return [_read_part(data, part, header, offsets, multipart, path)
            for part, (header, offsets) in enumerate(zip(headers, tables, strict=True))]


def _read_part(data: bytes, part: int, header: dict, offsets: np.ndarray, multipart: bool, path):
    if header["compression"] != _NO_COMPRESSION:
        raise SceneError(f"{path}: a compressed EXR (compression {header['compression']}; only uncompressed "
                         f"files are read without OpenImageIO)")
    xmin, ymin, xmax, ymax = header["dataWindow"]
    width, height = xmax - xmin + 1, ymax - ymin + 1
    channels = header["channels"]
    pixels = np.empty((height, width, len(channels)), np.float32)
    for offset in offsets:
        at = int(offset)
        if multipart:
            if struct.unpack_from("<i", data, at)[0] != part:
                raise SceneError(f"{path}: a chunk of part {part} belongs to another part")
            at += 4
        y, size = struct.unpack_from("<ii", data, at)
        at += 8
        if size != width * sum(dtype.itemsize for _, dtype in channels) or not 0 <= y - ymin < height:
            raise SceneError(f"{path}: a scanline chunk of an unexpected size or row")
        for c, (_, dtype) in enumerate(channels):
            pixels[y - ymin, :, c] = np.frombuffer(data, dtype, width, at)
            at += width * dtype.itemsize
    return [name for name, _ in channels], pixels


def _header(data: bytes, pos: int, path) -> tuple[dict, int]:
    """The attributes this reader needs (channels, compression, dataWindow) and the position after the
    header's closing NUL."""
    header = {}
    while data[pos] != 0:
        name, pos = _string(data, pos)
        kind, pos = _string(data, pos)
        size = struct.unpack_from("<i", data, pos)[0]
        pos += 4
        value = data[pos:pos + size]
        pos += size
        if kind == "chlist":
            header["channels"] = _channels(value, path)
        elif kind == "compression":
            header["compression"] = value[0]
        elif name == "dataWindow":
            header["dataWindow"] = struct.unpack("<4i", value)
    missing = {"channels", "compression", "dataWindow"} - set(header)
    if missing:
        raise SceneError(f"{path}: an EXR header without {', '.join(sorted(missing))}")
    return header, pos + 1


def _channels(value: bytes, path) -> list[tuple[str, np.dtype]]:
    out, pos = [], 0
    while value[pos] != 0:
        name, pos = _string(value, pos)
        kind, _, _, x_sampling, y_sampling = struct.unpack_from("<iB3sii", value, pos)
        pos += 16
        if kind not in _SAMPLE_TYPES or (x_sampling, y_sampling) != (1, 1):
            raise SceneError(f"{path}: channel {name!r} of type {kind} sampled {x_sampling} x {y_sampling}")
        out.append((name, _SAMPLE_TYPES[kind]))
    return out


def _string(data: bytes, pos: int) -> tuple[str, int]:
    end = data.index(b"\0", pos)
    return data[pos:end].decode("utf-8", "replace"), end + 1
