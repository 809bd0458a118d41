"""The method-choice model (addon/engine/choice.py): its scene features on scenes with known answers,
the fit on data made by a known model, and the choice for error and time budgets."""

import math

import numpy as np
import pytest

from addon.engine import choice
from addon.engine.config import RsmConfig
from addon.engine.errors import ConfigError
from addon.engine.scene import Light, Scene


def quad(a, b, c, d):
    return [[a, b, c], [a, c, d]]


def closed_box(lo=-1.0, hi=1.0):
    """The six faces of the cube [lo, hi]^3 as 12 triangles."""
    p = np.array([[x, y, z] for x in (lo, hi) for y in (lo, hi) for z in (lo, hi)], float)
    faces = [(0, 1, 3, 2), (4, 5, 7, 6), (0, 1, 5, 4), (2, 3, 7, 6), (0, 2, 6, 4), (1, 3, 7, 5)]
    return np.array([t for f in faces for t in quad(*p[list(f)])], np.float32)


def scene_of(triangles, lights=(), emission=None, world=(0.0, 0.0, 0.0)):
    n = len(triangles)
    return Scene(positions_m=triangles, normals=np.zeros_like(triangles), albedo=np.full((n, 3), 0.5, np.float32),
                 emission=np.zeros((n, 3), np.float32) if emission is None else emission, lights=list(lights),
                 world_color=np.array(world, np.float32))


def test_fibonacci_directions_are_unit_and_balanced():
    # The spiral's points are unit vectors whose mean is the origin up to the spiral's O(1/n) imbalance.
    d = choice.fibonacci_directions(64)
    assert np.allclose(np.linalg.norm(d, axis=1), 1.0, atol=1e-12)
    assert np.linalg.norm(d.mean(axis=0)) < 1.0 / 64


def test_rays_from_inside_a_closed_box_all_hit_and_a_floor_takes_half():
    # Exact answers: every ray from the centre of a closed cube meets a face; from above an infinite-like
    # floor exactly the downward half (the spiral has 32 points with z < 0 of 64).
    dirs = choice.fibonacci_directions(64)
    assert choice.rays_hit(np.zeros(3), dirs, closed_box()).all()
    floor = np.array(quad(*np.array([[-1e4, -1e4, 0], [1e4, -1e4, 0], [1e4, 1e4, 0], [-1e4, 1e4, 0]])), np.float32)
    hit = choice.rays_hit(np.array([0.0, 0.0, 1.0]), dirs, floor)
    assert hit.sum() == 32 and np.all(hit == (dirs[:, 2] < 0))


def test_rays_hit_is_the_same_in_any_chunking():
    dirs = choice.fibonacci_directions(64)
    tris = closed_box()[:7]  # an open box: some rays escape
    assert np.array_equal(choice.rays_hit(np.zeros(3), dirs, tris, chunk=2), choice.rays_hit(np.zeros(3), dirs, tris))


def test_enclosure_of_a_closed_box_is_one_and_of_a_lone_triangle_small():
    box = choice.scene_features(scene_of(closed_box(), [Light("POINT", np.zeros(3), np.array([0, 0, -1.0]),
                                                               np.ones(3), power_w=10.0)]))
    assert box["enclosure"] == 1.0
    tri = np.array([[[0, 0, 0], [1, 0, 0], [0, 1, 0]]], np.float32)
    lone = choice.scene_features(scene_of(tri))
    assert lone["enclosure"] <= 0.5  # at most the half of the sphere below the plane, from points on it


def test_light_shares_name_the_only_source():
    point = Light("POINT", np.zeros(3), np.array([0, 0, -1.0]), np.ones(3), power_w=100.0)
    shares = choice.light_shares(scene_of(closed_box(), [point]))
    assert shares == {"lamp": 1.0, "sun": 0.0, "world": 0.0, "shaped": 0.0}
    world = choice.light_shares(scene_of(closed_box(), world=(0.05, 0.05, 0.05)))
    assert world["world"] == 1.0
    glow = np.zeros((12, 3), np.float32)
    glow[0] = 1.0
    assert choice.light_shares(scene_of(closed_box(), emission=glow))["shaped"] == 1.0


def test_light_faces_count_what_light_views_render():
    # A point light: six cube faces; a sun: one; a 2 x 2 area light: 4 patches x 5 faces (the one
    # behind the emitter dropped).
    box = closed_box()
    point = Light("POINT", np.zeros(3), np.array([0, 0, -1.0]), np.ones(3), power_w=10.0)
    sun = Light("SUN", np.zeros(3), np.array([0, 0, -1.0]), np.ones(3), sun_strength=1.0)
    area = Light("AREA", np.array([0, 0, 0.9]), np.array([0, 0, -1.0]), np.ones(3), power_w=10.0,
                 size_x_m=0.5, size_y_m=0.5)
    rsm = RsmConfig(area_patches=2, world_suns=0)
    assert choice.light_faces(scene_of(box, [point]), rsm) == 6
    assert choice.light_faces(scene_of(box, [sun]), rsm) == 1
    assert choice.light_faces(scene_of(box, [area]), rsm) == 4 * 5


def synthetic(rows, scenes, a, b, c):
    """Records made by the model's own form with known a (per row), b (one slope per feature) and c."""
    recs = []
    for s, f in scenes.items():
        x = np.array([f[k] for k in choice.FEATURES])
        for k, (method, setting) in rows.items():
            recs.append({"scene": s, "method": method, "setting": setting,
                         "rel_rmse_8": math.exp(a[k] + b @ x), "total_ms": math.exp(c[k])})
    return recs


def features(rng):
    f = {k: float(rng.uniform(0, 1)) for k in choice.FEATURES}
    f.update({k: float(rng.uniform(1, 3)) for k in choice.TIME_FEATURES})
    f["log_pixels"] = math.log10(choice.TIME_REFERENCE_PIXELS)
    return f


def test_fit_recovers_a_noiseless_model():
    # Records generated by log err = a_row + b . x with one method: with a negligible ridge the fit
    # reproduces every record's error (the design has more records than unknowns) to 1e-6 relative.
    rng = np.random.default_rng(1)
    scenes = {f"s{i}": features(rng) for i in range(12)}
    rows = {"m x=1": ("m", {"g.x": 1}), "m x=2": ("m", {"g.x": 2}), "m x=3": ("m", {"g.x": 3})}
    a = {"m x=1": -1.0, "m x=2": -2.0, "m x=3": -3.0}
    c = {"m x=1": 1.0, "m x=2": 2.0, "m x=3": 3.0}
    b = rng.normal(0, 0.5, len(choice.FEATURES))
    recs = synthetic(rows, scenes, a, b, c)
    model = choice.fit(recs, scenes, ridge=1e-9)
    for r in recs:
        err, ms = model.predict(choice.row_key(r["method"], r["setting"]), scenes[r["scene"]])
        assert err == pytest.approx(r["rel_rmse_8"], rel=1e-6)
        assert ms == pytest.approx(r["total_ms"], rel=1e-6)


def test_pixel_factor_splits_an_update_into_a_fixed_and_a_per_pixel_part():
    # A quarter of the update at the reference pixels grows with them: at 4x the pixels it takes
    # 0.75 + 0.25 x 4 = 1.75x as long, at a quarter 0.75 + 0.0625 = 0.8125x; shares 0 and 1 bound it.
    ref = math.log10(choice.TIME_REFERENCE_PIXELS)
    assert choice.pixel_factor(0.25, ref) == pytest.approx(1.0)
    assert choice.pixel_factor(0.25, ref + math.log10(4)) == pytest.approx(1.75)
    assert choice.pixel_factor(0.25, ref - math.log10(4)) == pytest.approx(0.8125)
    assert choice.pixel_factor(0.0, ref + 2) == pytest.approx(1.0)
    assert choice.pixel_factor(1.0, ref + 2) == pytest.approx(100.0)


def test_fit_takes_times_to_the_reference_pixels_and_predicts_at_the_scenes():
    # Records timed at each scene's own pixels (1/2 to 2x the reference) by t = exp(c_row) x
    # pixel_factor(s_method): fitted with those shares, every time is reproduced to 1e-6 and the model
    # carries the time of a 1920 x 1080 image as the split says (no slope on the pixels is fitted).
    rng = np.random.default_rng(4)
    scenes = {f"s{i}": features(rng) for i in range(8)}
    for i, f in enumerate(scenes.values()):
        f["log_pixels"] = math.log10(choice.TIME_REFERENCE_PIXELS) + math.log10(2) * (i / 3.5 - 1)
    shares = {"m": 0.2, "n": 0.9}
    rows = {"m x=1": ("m", {"g.x": 1}), "n y=2": ("n", {"h.y": 2})}
    c = {"m x=1": math.log(50.0), "n y=2": math.log(400.0)}
    recs = synthetic(rows, scenes, {k: -1.0 for k in rows}, np.zeros(len(choice.FEATURES)), c)
    for r in recs:
        r["total_ms"] *= choice.pixel_factor(shares[r["method"]], scenes[r["scene"]]["log_pixels"])
    model = choice.fit(recs, scenes, ridge=1e-9, per_pixel_share=shares)
    for r in recs:
        assert model.predict(choice.row_key(r["method"], r["setting"]), scenes[r["scene"]])[1] == \
            pytest.approx(r["total_ms"], rel=1e-6)
    hd = {**scenes["s0"], "log_pixels": math.log10(1920 * 1080)}
    ratio = 1920 * 1080 / choice.TIME_REFERENCE_PIXELS
    assert model.predict("n y=2", hd)[1] == pytest.approx(400.0 * (0.1 + 0.9 * ratio), rel=1e-6)


def test_each_row_time_may_grow_with_the_scene_its_own_way():
    # One method, two rows: one's time grows as triangles^1 (an RSM draw), the other's not at all (a
    # march over a fixed grid). Each row's own slopes, held by a negligible row ridge, reproduce every
    # time to 1e-6; held to the method's shared slope by a huge one, the fit must split the difference
    # and misses the times by far more than 10 % on the scenes at the ends of the triangle range.
    rng = np.random.default_rng(6)
    scenes = {f"s{i}": features(rng) for i in range(10)}
    rows = {"m x=1": ("m", {"g.x": 1}), "m x=2": ("m", {"g.x": 2})}
    recs = synthetic(rows, scenes, {k: -1.0 for k in rows}, np.zeros(len(choice.FEATURES)), {k: 5.0 for k in rows})
    for r in recs:
        if r["setting"]["g.x"] == 1:
            r["total_ms"] *= 10.0 ** scenes[r["scene"]]["log_triangles"]

    def worst(model):
        return max(abs(model.predict(choice.row_key(r["method"], r["setting"]), scenes[r["scene"]])[1]
                       / r["total_ms"] - 1) for r in recs)

    assert worst(choice.fit(recs, scenes, ridge=1e-9, time_row_ridge=1e-9)) < 1e-6
    assert worst(choice.fit(recs, scenes, ridge=1e-9, time_row_ridge=1e9)) > 0.1


def three_rows(seed: int):
    """(model, one scene's features): rows "m x=1..3" with errors 0.3, 0.15, 0.05 and times 10, 100,
    1000 ms on every one of 6 random scenes, fitted with a negligible ridge (margin 1)."""
    rng = np.random.default_rng(seed)
    scenes = {f"s{i}": features(rng) for i in range(6)}
    rows = {"m x=1": ("m", {"g.x": 1}), "m x=2": ("m", {"g.x": 2}), "m x=3": ("m", {"g.x": 3})}
    a = {"m x=1": math.log(0.3), "m x=2": math.log(0.15), "m x=3": math.log(0.05)}
    c = {"m x=1": math.log(10), "m x=2": math.log(100), "m x=3": math.log(1000)}
    model = choice.fit(synthetic(rows, scenes, a, np.zeros(len(choice.FEATURES)), c), scenes, ridge=1e-9)
    return model, scenes["s0"]


def test_choose_the_fastest_within_an_error_budget_and_the_best_within_a_time_budget():
    model, f = three_rows(2)  # errors 0.3, 0.15, 0.05 on every scene; times 10, 100, 1000 ms
    assert choice.choose(model, f, error_budget=0.2).key == "m x=2"
    assert choice.choose(model, f, error_budget=0.4).key == "m x=1"
    assert choice.choose(model, f, time_budget_ms=500).key == "m x=2"
    model.margin = 1.5  # 0.15 x 1.5 > 0.2: only the slow row is expected within 0.2
    assert choice.choose(model, f, error_budget=0.2).key == "m x=3"
    miss = choice.choose(model, f, error_budget=0.01)
    assert miss.key == "m x=3" and not miss.meets_budget and "no setting" in miss.why
    with pytest.raises(ConfigError):
        choice.choose(model, f)
    with pytest.raises(ConfigError):
        choice.choose(model, f, error_budget=0.1, time_budget_ms=10)


def recording(asked: list):
    """estimates(values): an `estimate` for choice.verify that answers from `values` and appends each
    key asked to `asked`, so a test sees which rows were rendered and in what order."""
    def estimates(values):
        def estimate(key):
            asked.append(key)
            return values[key]
        return estimate
    return estimates


def test_verify_takes_the_fastest_candidate_whose_estimate_is_within_the_budget(monkeypatch):
    # Rows predicted 0.3 / 0.15 / 0.05 in 10 / 100 / 1000 ms on every scene, margin 1. The mechanism with
    # one stage at a loosening of 2 (VERIFY_STAGES itself is swept on the benchmark): at E = 0.2 the
    # candidates are those predicted within 2 x 0.2 = 0.4, all three, fastest first.
    monkeypatch.setattr(choice, "VERIFY_STAGES", (2.0,))
    model, f = three_rows(4)
    asked = []
    estimates = recording(asked)

    # The fastest row measures within the budget although the model expects 0.3: it is taken, and
    # nothing slower is rendered.
    key, tried = choice.verify(model, f, 0.2, estimates({"m x=1": 0.18, "m x=2": 0.1, "m x=3": 0.05}))
    assert key == "m x=1" and asked == ["m x=1"] and tried == [{"row": "m x=1", "estimated_rel_rmse_8": 0.18}]
    # The model's own choice (x=2) measures 0.25 here: the next candidate is taken.
    asked.clear()
    key, tried = choice.verify(model, f, 0.2, estimates({"m x=1": 0.35, "m x=2": 0.25, "m x=3": 0.08}))
    assert key == "m x=3" and asked == ["m x=1", "m x=2", "m x=3"]
    # VERIFY_ACCEPT below 1 (swept): an estimate within the budget but above that share of it is not taken.
    asked.clear()
    monkeypatch.setattr(choice, "VERIFY_ACCEPT", 0.95)
    key, _ = choice.verify(model, f, 0.2, estimates({"m x=1": 0.195, "m x=2": 0.15, "m x=3": 0.05}))
    assert key == "m x=2" and asked == ["m x=1", "m x=2"]
    monkeypatch.setattr(choice, "VERIFY_ACCEPT", 1.0)
    # None within: None, every candidate tried once. A row without an estimate is skipped, not counted.
    asked.clear()
    key, tried = choice.verify(model, f, 0.2, estimates({"m x=1": 0.5, "m x=2": None, "m x=3": 0.3}))
    assert key is None and [t["row"] for t in tried] == ["m x=1", "m x=3"]
    # At E = 0.1 only rows predicted within 0.2 are candidates: the 0.3 row is never rendered.
    asked.clear()
    choice.verify(model, f, 0.1, estimates({"m x=1": 0.01, "m x=2": 0.5, "m x=3": 0.5}))
    assert asked == ["m x=2", "m x=3"]


def test_verify_tries_a_looser_stage_only_when_none_of_the_first_passes(monkeypatch):
    # The same rows (predicted 0.3 / 0.15 / 0.05 in 10 / 100 / 1000 ms), stages of 1 and 2 budgets. At
    # E = 0.2 the first stage holds the rows predicted within 0.2 (x=2, x=3), fastest first; the 0.3 row,
    # though fastest, comes only in the second stage (within 0.4).
    monkeypatch.setattr(choice, "VERIFY_STAGES", (1.0, 2.0))
    monkeypatch.setattr(choice, "VERIFY_FASTER", 0)  # the stages alone (the faster rows: the next test)
    model, f = three_rows(4)
    asked = []
    estimates = recording(asked)

    key, _ = choice.verify(model, f, 0.2, estimates({"m x=1": 0.1, "m x=2": 0.15, "m x=3": 0.05}))
    assert key == "m x=2" and asked == ["m x=2"]
    asked.clear()
    key, tried = choice.verify(model, f, 0.2, estimates({"m x=1": 0.1, "m x=2": 0.25, "m x=3": 0.3}))
    assert key == "m x=1" and asked == ["m x=2", "m x=3", "m x=1"] and len(tried) == 3
    # A row is tried once, though every stage holds it; the cap counts rows of every stage.
    asked.clear()
    monkeypatch.setattr(choice, "VERIFY_MAX_TRIES", 2)
    key, tried = choice.verify(model, f, 0.2, estimates({"m x=1": 0.1, "m x=2": 0.25, "m x=3": 0.3}))
    assert key is None and asked == ["m x=2", "m x=3"]


def test_verify_then_tries_rows_much_faster_than_the_one_taken(monkeypatch):
    # The same rows (predicted 0.3 / 0.15 / 0.05 in 10 / 100 / 1000 ms), one stage of 1 budget: at E = 0.2
    # x=2 (100 ms) is taken first; x=1, predicted faster than VERIFY_FASTER_SHARE (0.5) of its time, is
    # then tried though the model expects it above the budget, and replaces it when within.
    monkeypatch.setattr(choice, "VERIFY_STAGES", (1.0,))
    model, f = three_rows(4)
    asked = []
    estimates = recording(asked)
    key, tried = choice.verify(model, f, 0.2, estimates({"m x=1": 0.1, "m x=2": 0.15, "m x=3": 0.05}))
    assert key == "m x=1" and asked == ["m x=2", "m x=1"] and len(tried) == 2
    # Not within: the row taken first stays.
    asked.clear()
    key, _ = choice.verify(model, f, 0.2, estimates({"m x=1": 0.3, "m x=2": 0.15, "m x=3": 0.05}))
    assert key == "m x=2" and asked == ["m x=2", "m x=1"]
    # The slower row x=3 is never a "faster" one; with x=3 taken at E = 0.1 both faster rows are tried,
    # fastest first, and the first within replaces it.
    asked.clear()
    key, _ = choice.verify(model, f, 0.1, estimates({"m x=1": 0.2, "m x=2": 0.08, "m x=3": 0.05}))
    assert key == "m x=2" and asked == ["m x=3", "m x=1", "m x=2"]
    # At most VERIFY_FASTER of them.
    asked.clear()
    monkeypatch.setattr(choice, "VERIFY_FASTER", 1)
    key, _ = choice.verify(model, f, 0.1, estimates({"m x=1": 0.2, "m x=2": 0.08, "m x=3": 0.05}))
    assert key == "m x=3" and asked == ["m x=3", "m x=1"]


def test_verify_renders_at_most_its_cap():
    rng = np.random.default_rng(5)
    scenes = {f"s{i}": features(rng) for i in range(4)}
    n = choice.VERIFY_MAX_TRIES + 3
    rows = {f"m x={i}": ("m", {"g.x": i}) for i in range(n)}
    a = {k: math.log(0.1) for k in rows}
    c = {k: float(i) for i, k in enumerate(rows)}
    model = choice.fit(synthetic(rows, scenes, a, np.zeros(len(choice.FEATURES)), c), scenes, ridge=1e-9)
    key, tried = choice.verify(model, scenes["s0"], 0.1, lambda k: 1.0)
    assert key is None and len(tried) == choice.VERIFY_MAX_TRIES


def test_with_none_within_the_row_of_least_estimate_runs():
    tried = [{"row": "a", "estimated_rel_rmse_8": 0.4}, {"row": "b", "estimated_rel_rmse_8": 0.25},
             {"row": "c", "estimated_rel_rmse_8": 0.3}]
    assert choice.least_estimated(tried) == "b"
    assert choice.least_estimated([]) is None  # nothing tried: the caller keeps the model's choice


def test_model_round_trips_through_json():
    rng = np.random.default_rng(3)
    scenes = {f"s{i}": features(rng) for i in range(4)}
    rows = {"m x=1": ("m", {"g.x": 1}), "n y=2": ("n", {"h.y": 2})}
    recs = synthetic(rows, scenes, {"m x=1": -1.0, "n y=2": -2.0}, np.ones(len(choice.FEATURES)) * 0.1,
                     {"m x=1": 1.0, "n y=2": 2.0})
    model = choice.fit(recs, scenes, per_pixel_share={"m": 0.3})
    again = choice.Model.from_json(model.to_json())
    assert again.per_pixel_share == {"m": 0.3}
    for k in model.rows:
        assert again.predict(k, scenes["s1"]) == model.predict(k, scenes["s1"])


def test_check_spp_from_the_pilots_noise():
    # Noise falls as 1 / sqrt(spp): the pilot pair's mean at CHECK_PILOT_SPP (4) reads 0.2; a mean as
    # noisy as 0.05 needs (0.2 / 0.05)^2 = 16x the samples, 64 per render.
    assert choice.check_spp(0.2, 0.05) == 64
    assert choice.check_spp(0.2, 0.3) == choice.CHECK_PILOT_SPP  # never fewer than the pilot's
    assert choice.check_spp(10.0, 0.01) == choice.CHECK_MAX_SPP
    with pytest.raises(ConfigError):
        choice.check_spp(0.2, 0.0)


def test_path_traced_check_sizes_its_pair_from_the_pilot():
    # A fake path tracer: light 2 plus Gaussian noise of sd 8 / sqrt(spp) per pixel (Monte Carlo), 64 x 64
    # px, every pixel covered. The pilot pair at 4 spp: each full block's mean has sd (8 / 2) / 8 = 0.5,
    # their mean's 0.354, rel_noise_8 0.177. To resolve 0.1 at CHECK_NOISE 0.25 the pair's mean needs
    # 0.025: spp = 4 x (0.177 / 0.025)^2 ~ 200 (the pilot's noise is itself measured from 64 blocks x 3:
    # +-10 %, the spp +-20 %).
    calls = []

    def render(spp, seed):
        calls.append((spp, seed))
        rng = np.random.default_rng(seed)
        return 2.0 + rng.normal(0.0, 8.0 / np.sqrt(spp), (64, 64, 3)), np.ones((64, 64), bool), 0.5

    check = choice.path_traced_check(0.1, render)
    assert calls[:2] == [(choice.CHECK_PILOT_SPP, s) for s in choice.CHECK_SEEDS[0]]
    assert [c[1] for c in calls[2:]] == list(choice.CHECK_SEEDS[1]) and calls[2][0] == calls[3][0]
    assert choice.CHECK_NOISE == 0.25 and 140 <= check["spp"] <= 280 and check["time_s"] == 2.0
    assert check["noise"] == pytest.approx(0.025, rel=0.3)
    assert choice.check_stats(check) == {"check_spp": check["spp"], "check_noise": check["noise"],
                                         "check_time_s": 2.0}
    # An image of exactly 2.2 is 10 % off the truth everywhere: the estimate reads 0.1, the checks'
    # noise (0.025) taken out; where it covers nothing (alpha 0) there is nothing to judge.
    ours = np.concatenate([np.full((64, 64, 3), 2.2), np.ones((64, 64, 1))], axis=2)
    assert choice.path_traced_estimate(ours, check) == pytest.approx(0.1, rel=0.15)
    ours[..., 3] = 0.0
    assert choice.path_traced_estimate(ours, check) is None
    # A self-check (resolve None) resolves the error the pilot pair finds in `ours`: 0.1 here, so about the
    # spp above (the pilot's estimate of 0.1, from a pair whose mean is 0.177 noisy, is within +-30 %: the
    # spp, which goes as 1 / resolve^2, within a factor 2).
    ours[..., 3] = 1.0
    assert 0.5 <= choice.path_traced_check(None, render, ours=ours)["spp"] / check["spp"] <= 2.0
    # A path tracer that covers nothing gives no check.
    assert choice.path_traced_check(0.1, lambda spp, seed: (np.ones((8, 8, 3)), np.zeros((8, 8), bool), 0.1)) is None
