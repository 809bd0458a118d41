"""exr.py, the numpy reader of uncompressed EXR, against files OpenImageIO writes (the venv has it): the
same values back, exactly, in single- and multi-part files, float and half channels, and one clear
error for what it does not read."""

from __future__ import annotations

import numpy as np
import pytest

oiio = pytest.importorskip("OpenImageIO")

from addon.bridge import exr, images  # noqa: E402
from addon.engine.errors import SceneError  # noqa: E402


def _spec(names, width=5, height=3, fmt=None, compression="none", part=None):
    spec = oiio.ImageSpec(width, height, len(names), fmt or oiio.FLOAT)
    spec.channelnames = names
    spec.attribute("compression", compression)
    if part is not None:
        spec.attribute("oiio:subimagename", part)
    return spec


def _write(path, specs, pixels):
    out = oiio.ImageOutput.create(str(path))
    assert out.open(str(path), specs), out.geterror()
    for i, px in enumerate(pixels):
        if i:
            assert out.open(str(path), specs[i], "AppendSubimage"), out.geterror()
        assert out.write_image(px), out.geterror()
    out.close()


def _pixels(rng, height, width, channels):
    # values no float32 round trip can change, and no two alike: a swapped row or channel shows
    return rng.standard_normal((height, width, channels)).astype(np.float32)


def test_single_part_layers_come_back_exactly_in_rgba_order(tmp_path):
    rng = np.random.default_rng(1)
    names = ["ViewLayer.Combined.R", "ViewLayer.Combined.G", "ViewLayer.Combined.B", "ViewLayer.Combined.A",
             "ViewLayer.Normal.X", "ViewLayer.Normal.Y", "ViewLayer.Normal.Z"]
    px = _pixels(rng, 3, 5, len(names))
    _write(tmp_path / "a.exr", [_spec(names)], [px])
    passes = images.read_multilayer(tmp_path / "a.exr")
    assert sorted(passes) == ["Combined", "Normal"]
    np.testing.assert_array_equal(passes["Combined"], px[..., :4])  # R, G, B, A though the file sorts A first
    np.testing.assert_array_equal(passes["Normal"], px[..., 4:])


def test_multi_part_and_half_channels(tmp_path):
    rng = np.random.default_rng(2)
    a = _pixels(rng, 4, 6, 3)
    b = _pixels(rng, 4, 6, 3).astype(np.float16)
    names_a = [f"ViewLayer.Diffuse Indirect.{c}" for c in "RGB"]
    names_b = [f"ViewLayer.Diffuse Color.{c}" for c in "RGB"]
    _write(tmp_path / "m.exr", [_spec(names_a, 6, 4, part="one"), _spec(names_b, 6, 4, oiio.HALF, part="two")],
           [a, b])
    parts = exr.read_parts(tmp_path / "m.exr")
    assert len(parts) == 2
    passes = images.read_multilayer(tmp_path / "m.exr")
    np.testing.assert_array_equal(passes["Diffuse Indirect"], a)
    np.testing.assert_array_equal(passes["Diffuse Color"], b.astype(np.float32))


def test_what_it_does_not_read_is_one_scene_error(tmp_path):
    px = np.zeros((2, 2, 3), np.float32)
    _write(tmp_path / "zip.exr", [_spec(["R", "G", "B"], 2, 2, compression="zip")], [px])
    with pytest.raises(SceneError, match="compressed EXR"):
        exr.read_parts(tmp_path / "zip.exr")
    (tmp_path / "junk.exr").write_bytes(b"not an exr")
    with pytest.raises(SceneError, match="not an OpenEXR file"):
        exr.read_parts(tmp_path / "junk.exr")
    with pytest.raises(SceneError, match="no such image"):
        images.read_multilayer(tmp_path / "missing.exr")
