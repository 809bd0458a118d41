"""A glossy layer reflects bounced light as its base colour: Cycles (as the reference renders it) and
Bounce agree.

cornell-glossy is cornell with a Specular IOR Level 1 layer on the floor and the boxes (Diffuse Color
0.925 x base colour head-on, less at a slant). After a diffuse bounce, with reflective caustics off as
the reference renders, Cycles does not build Principled BSDF's specular layer and so does not attenuate
the diffuse lobe under it: a back-wall pixel's light, which comes off the floor and the boxes, is the
same as in the plain cornell box. Bounce's indirect methods reflect with `Scene.bounce_albedo` for the
same reason. Before they used the camera's albedo and read the glossy box 7.6 % darker than the plain
one on the back wall (gather: bias 0.923 against Cycles at 128 px, 256 spp, where it is 0.98 on cornell).
"""

from __future__ import annotations

import numpy as np
import pytest

pytestmark = [pytest.mark.blender, pytest.mark.slow]

RES = 64


def _back_wall(normal: np.ndarray) -> np.ndarray:
    """Pixels of the back wall (normal exactly -y; the boxes' faces are turned 17 degrees)."""
    return normal[..., 1] < -0.999


def test_a_glossy_layer_bounces_light_as_its_base_colour(tmp_path):
    from addon.bridge import images, scenes
    from addon.bridge.pipeline import render_file
    from addon.bridge.reference import render_reference
    from addon.engine.config import GIConfig

    back = {}
    for name in ("cornell", "cornell-glossy"):
        blend = tmp_path / f"{name}.blend"
        scenes.save(name, blend)
        render_reference(blend, tmp_path / f"ref-{name}", spp=64, bounces=1, res=RES, seed=0)
        (tmp_path / name).mkdir()
        render_file(blend, tmp_path / name, {"gi": GIConfig(method="lpv", resolution=RES)}, repeat=1)
        normal = images.read_exr(tmp_path / f"ref-{name}" / "normal.exr")
        back[name] = {
            "mask": _back_wall(normal),
            "cycles": images.read_exr(tmp_path / f"ref-{name}" / "indirect.exr")[..., :3],
            "bounce": images.read_exr(tmp_path / name / "indirect.exr")[..., :3],
        }
    mask = back["cornell"]["mask"]
    assert mask.sum() > 0.15 * RES * RES and np.array_equal(mask, back["cornell-glossy"]["mask"])
    ratios = {k: float(back["cornell-glossy"][k][mask].mean() / back["cornell"][k][mask].mean())
              for k in ("cycles", "bounce")}
    print(f"back wall, cornell-glossy / cornell: {ratios}")
    # Exact 1 for both. Cycles samples both scenes' back-wall paths with the same random numbers and,
    # past the wall, the same closures, so only float rounding differs; measured 1.0000. The rule this
    # guards against (the layer's attenuation kept) reads 0.925 x the floor's and boxes' share, < 0.95.
    assert ratios["cycles"] == pytest.approx(1.0, abs=0.005)
    # lpv is deterministic and the light it propagates is the same in both scenes; measured 1.0000.
    assert ratios["bounce"] == pytest.approx(1.0, abs=0.005)
