"""Bounce's bake (method rsm with voxel visibility, and method vct for indirect) against Cycles' own bake
of the Cornell box's Floor and BackWall, texel by texel (64 x 64 lightmaps over the walls' 0..1 UVs).

Cycles: `bpy.ops.object.bake(type='DIFFUSE', pass_filter={'INDIRECT'})` (then {'DIRECT'}) without
'COLOR' gives the light alone, the units of the Diffuse Indirect / Direct passes, which is what Bounce's
products are. Cycles is set up as for references (one diffuse bounce, no clamping, no denoising, no
adaptive sampling); its noise floor is the error between two seeds.
"""

import pytest

pytestmark = [pytest.mark.blender, pytest.mark.slow]

SIZE = 64
SPP = 256
OBJECTS = ("Floor", "BackWall")


def test_bake_matches_cycles_bake(tmp_path):
    import bpy

    from addon.bridge import images, scenes
    from addon.bridge.bake import bake_file
    from addon.bridge.reference import cycles_bake
    from addon.engine import metrics
    from addon.engine.config import GIConfig, RsmConfig

    blend = tmp_path / "cornell.blend"
    scenes.save("cornell", blend)
    ours, ours_ms = {}, {}
    for pass_name in ("indirect", "direct"):
        out = tmp_path / pass_name
        rsm = RsmConfig(visibility="voxel", voxel_cells=128, vpl_samples=1024)
        settings = {"gi": GIConfig(method="rsm"), "rsm": rsm}
        summary = bake_file(blend, out, list(OBJECTS), SIZE, settings, pass_name, progress=False)
        for name in OBJECTS:
            assert summary["objects"][name]["status"] == "ok", summary["objects"][name]
            ours[name, pass_name] = images.read_exr(out / f"{name}_{pass_name}.exr")
            ours_ms[name, pass_name] = summary["objects"][name]["time_ms"]
        ours_ms["setup", pass_name] = summary["setup_ms"]
    vct_out = tmp_path / "vct"
    summary = bake_file(blend, vct_out, list(OBJECTS), SIZE, {"gi": GIConfig(method="vct")}, "indirect",
                        progress=False)
    for name in OBJECTS:
        assert summary["objects"][name]["status"] == "ok", summary["objects"][name]
        ours[name, "vct"] = images.read_exr(vct_out / f"{name}_indirect.exr")

    bpy.ops.wm.open_mainfile(filepath=str(blend))
    figures = {}
    for name in OBJECTS:
        for pass_name, flt in (("indirect", {"INDIRECT"}), ("direct", {"DIRECT"})):
            ref, seconds = cycles_bake(name, flt, SPP, seed=0, size=SIZE)
            a = ours[name, pass_name]
            mask = (ref[..., 3] > 0.5) & (a[..., 3] > 0.5)
            assert mask.mean() > 0.99  # the walls' UVs fill the square: every texel is covered by both
            err = metrics.compare(a[..., :3], ref[..., :3], mask)
            figures[name, pass_name] = err
            line = (f"{name} {pass_name}: rel_rmse_8 {err['rel_rmse_8']:.4f} bias {err['bias']:.4f} "
                    f"rel_rmse {err['rel_rmse']:.4f}; ours {ours_ms[name, pass_name]:.0f} ms "
                    f"(+ setup {ours_ms['setup', pass_name]:.0f} ms), Cycles {SPP} spp {seconds * 1e3:.0f} ms")
            if pass_name == "indirect":
                ref2, _ = cycles_bake(name, flt, SPP, seed=1, size=SIZE)
                floor = metrics.compare(ref2[..., :3], ref[..., :3], mask)
                line += f"; Cycles noise floor rel_rmse_8 {floor['rel_rmse_8']:.4f} rel_rmse {floor['rel_rmse']:.4f}"
                figures[name, "vct"] = metrics.compare(ours[name, "vct"][..., :3], ref[..., :3], mask)
                line += (f"; vct rel_rmse_8 {figures[name, 'vct']['rel_rmse_8']:.4f} "
                         f"bias {figures[name, 'vct']['bias']:.4f}")
            print(line)
    # Measured (64 x 64 texels, RSM 256, 1024 VPLs, 128 voxel cells; Cycles CPU 256 spp, seeds 0/1;
    # 2-core CPU, llvmpipe):
    #   Floor    indirect rel_rmse_8 0.107 bias 0.948 (Cycles noise floor rel_rmse_8 0.008)
    #            direct   rel_rmse_8 0.008 bias 1.000
    #   BackWall indirect rel_rmse_8 0.034 bias 0.978 (noise floor 0.026)
    #            direct   rel_rmse_8 0.011 bias 1.001
    # The Floor's indirect error sits in its first texel row along the back and left walls (ours up to 5x
    # too bright: VPLs 1.5 cm away on the meeting wall, the gather's near-field singularity); the direct
    # error at the spot cone's and the boxes' shadow edges (Cycles jitters samples over each texel, we
    # point-sample its centre).
    # vct's bake (64 cells, 16 cones, the same lightmap texels): Floor rel_rmse_8 0.156 bias 0.918,
    # BackWall 0.160 / 0.876 -- the back wall's light comes from the floor's spot, 2 m away through
    # coarse voxels that straddle the open front (docs/VCT.md: light escapes the box; bias < 1 on the
    # camera image too). Bounds: the figures + ~20 %, bias never above 1 (nothing adds light).
    for name in OBJECTS:
        v = figures[name, "vct"]
        assert v["rel_rmse_8"] <= VCT_BOUNDS[name]["indirect_rmse8"], (name, v)
        assert VCT_BOUNDS[name]["bias_min"] <= v["bias"] <= 1.0, (name, v)
    for name in OBJECTS:
        ind, dirc = figures[name, "indirect"], figures[name, "direct"]
        assert ind["rel_rmse_8"] <= BOUNDS[name]["indirect_rmse8"], (name, ind)
        assert abs(ind["bias"] - 1.0) <= 0.08, (name, ind)
        assert dirc["rel_rmse_8"] <= BOUNDS[name]["direct_rmse8"], (name, dirc)
        assert abs(dirc["bias"] - 1.0) <= 0.03, (name, dirc)


VCT_BOUNDS = {
    "Floor": {"indirect_rmse8": 0.19, "bias_min": 0.85},
    "BackWall": {"indirect_rmse8": 0.19, "bias_min": 0.82},
}
BOUNDS = {
    "Floor": {"indirect_rmse8": 0.13, "direct_rmse8": 0.010},
    "BackWall": {"indirect_rmse8": 0.045, "direct_rmse8": 0.014},
}
