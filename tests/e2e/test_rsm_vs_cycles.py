"""Method `rsm` (VPL gather, no visibility) against Cycles' Diffuse Indirect on the Cornell box.

Without visibility the gather lights surfaces the bounce cannot reach, so it is too bright; BASELINE.md
measured rel_rmse_8 0.215 and bias 1.15 for this gather. This test pins that behaviour so a change that
makes it worse (or a units error, which shows as a bias far from ~1.15) fails, and reports the figures.
"""

import pytest

pytestmark = [pytest.mark.blender, pytest.mark.slow]


def test_rsm_gather_on_cornell(tmp_path):
    from addon.bridge import images, scenes
    from addon.bridge.pipeline import render_file
    from addon.bridge.reference import render_reference
    from addon.engine import metrics
    from addon.engine.config import GIConfig

    blend = tmp_path / "cornell.blend"
    scenes.save("cornell", blend)
    (tmp_path / "ours").mkdir()
    stats = render_file(blend, tmp_path / "ours", {"gi": GIConfig(method="rsm", resolution=64)}, repeat=1)
    render_reference(blend, tmp_path / "ref", spp=256, bounces=1, res=64, seed=0)
    ours = images.read_exr(tmp_path / "ours" / "indirect.exr")
    ref = images.read_exr(tmp_path / "ref" / "indirect.exr")
    err = metrics.compare(ours, ref, ref[..., 3] > 0.5)
    print(f"rsm vs Cycles: {err}, {stats['total_ms']:.1f} ms")
    # Measured at 128 px: rel_rmse_8 0.18, bias 1.13 (reference 256 spp: its own rel_rmse_8 ~0.02).
    assert err["rel_rmse_8"] <= 0.26
    assert 1.0 <= err["bias"] <= 1.3
