"""tools/readme_figures.py: the generated figure blocks of README.md and docs/ equal what the tool makes
from the committed results.json files (a hand edit or a stale table fails here), and the rewrite is
idempotent."""

import importlib.util
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
_spec = importlib.util.spec_from_file_location("readme_figures", ROOT / "tools" / "readme_figures.py")
readme_figures = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(readme_figures)

MACHINE = {"cpu": "Some CPU", "cores": 2, "bounce_renderer": "llvmpipe", "blender": "5.0.1", "date": "2026-12-01",
           "commit": "0123456789abcdef" * 2 + "01234567", "dirty": False, "load_average_1min": [0.5, 2.3]}


def _record(scene, method, default=True, update_ms=None, rel_rmse_8=0.5, bias=0.9):
    return {"scene": scene, "method": method, "default": default, "image_size": [256, 192],
            "update_ms": update_ms, "rel_rmse_8": rel_rmse_8, "bias": bias}


def _results(records):
    return {"command": "python -m addon bench X", "repeat": 5, "res": 128, "ref_spp": 128, "machine": MACHINE,
            "records": records}


@pytest.mark.parametrize("doc", readme_figures.documents(), ids=lambda d: d.name)
def test_generated_blocks_equal_the_tool_output(doc):
    text = doc.read_text()
    assert readme_figures.rewrite(text, readme_figures.render_blocks(doc)) == text, \
        f"{doc.name}'s figure blocks are stale or edited by hand: run .venv/bin/python tools/readme_figures.py"


def test_rewrite_is_idempotent_and_keeps_the_text_around_blocks():
    text = ("intro\n<!-- figures:a:begin -->\nold a\n<!-- figures:a:end -->\nmiddle\n"
            "<!-- figures:b:begin -->\nold b\n<!-- figures:b:end -->\ntail\n")
    once = readme_figures.rewrite(text, {"a": "new a\n"})
    assert once == text.replace("old a", "new a")
    assert readme_figures.rewrite(once, {"a": "new a\n"}) == once
    blocks = readme_figures.render_blocks()
    readme = readme_figures.rewrite(readme_figures.README.read_text(), blocks)
    assert readme_figures.rewrite(readme, blocks) == readme
    with pytest.raises(ValueError, match="no markers for block"):
        readme_figures.rewrite(text, {"c": "x\n"})


def test_update_costs_block():
    records = [_record("cornell", "direct", update_ms={"full": 15.0, "lights": 5.8, "camera": 10.8}),
               _record("cornell", "lpv", update_ms={"full": 172.0, "lights": 168.0, "camera": 19.0}),
               _record("cornell", "lpv", default=False, update_ms={"full": 1.0, "lights": 1.0, "camera": 1.0}),
               _record("sponza", "lpv", update_ms={"full": 200.0, "lights": 150.0, "camera": 40.0})]
    block = readme_figures.update_costs_block(_results(records))
    assert block.startswith("**Update costs** of each method at its default settings.\n\n"
                            "Produced by `python -m addon bench X`\non 2026-12-01 (commit 0123456789ab; Some CPU, "
                            "2 cores, load average 0.5 / 2.3 at the start / end; llvmpipe; Blender 5.0.1). "
                            "Medians of 5 updates of each kind;")
    assert "| cornell | 256 x 192 | direct | 15.0 | 5.8 | 10.8 | 72 % |" in block
    assert "| cornell | 256 x 192 | lpv | 172.0 | 168.0 | 19.0 | 11 % |" in block
    assert "| 1.0 |" not in block  # only the default rows
    assert block.endswith("lpv's camera update costs 11.0 % on cornell, 20.0 % on sponza of its full update "
                          "(target <= 15 %: not met).\n")
    # With probes beside lpv: probes' light update as a share of lpv's, per scene (84 / 168, 180 / 150).
    records += [_record("cornell", "probes", update_ms={"full": 900.0, "lights": 84.0, "camera": 9.0}),
                _record("sponza", "probes", update_ms={"full": 900.0, "lights": 180.0, "camera": 9.0})]
    block = readme_figures.update_costs_block(_results(records))
    assert block.endswith("probes' light update costs 50 % on cornell, 120 % on sponza of lpv's (target <= 100 %: "
                          "not met).\n")


def test_accuracy_block():
    records = [_record("cornell", "direct", rel_rmse_8=0.1024, bias=0.9957), _record("cornell", "lpv"),
               _record("cornell", "lpv", default=False, rel_rmse_8=9.0), _record("emissive", "direct"),
               _record("emissive", "lpv", rel_rmse_8=None)]
    lines = readme_figures.accuracy_block(_results(records)).splitlines()
    assert lines[0] == "**Accuracy against Cycles** of each method at its default settings."
    assert lines[5:] == ["| scene | direct | lpv |", "| --- | --- | --- |",
                         "| cornell | 0.102 / 0.996 | 0.500 / 0.900 |", "| emissive | 0.500 / 0.900 | – |"]


def test_accuracy_block_with_the_oidn_anchor():
    """Schema 2 records carry the speed-up against Cycles + OIDN: the cells gain it, with its bound;
    records of a run without that anchor (speedup_oidn None, or schema 1 without the key) keep two numbers."""
    def rec(scene, method, speedup_oidn):
        return {**_record(scene, method, rel_rmse_8=0.1024, bias=0.9957), "speedup_oidn": speedup_oidn}

    records = [rec("cornell", "direct", {"speedup": 1.94, "bound": "<"}),
               rec("cornell", "lpv", {"speedup": 12.345, "bound": "="}),
               rec("emissive", "direct", {"speedup": 300.0, "bound": ">"}),
               rec("emissive", "lpv", {"speedup": None, "bound": "="})]
    lines = readme_figures.accuracy_block(_results(records)).splitlines()
    assert "cells: rel_rmse_8 / bias / speed-up against Cycles + OIDN (" in lines[3]
    assert lines[7:] == ["| cornell | 0.102 / 0.996 / <= 1.94x | 0.102 / 0.996 / 12.3x |",
                         "| emissive | 0.102 / 0.996 / >= 300x | 0.102 / 0.996 / – |"]
    without = [{**r, "speedup_oidn": None} for r in records]
    assert "OIDN" not in readme_figures.accuracy_block(_results(without))


def test_methods_block_gives_medians_over_scenes():
    # direct on three scenes: errors 0.1, 0.3, 0.2 -> median 0.2; times 10, 30, 20 -> 20; speed-ups
    # 2 (=), 4 (=), 9 (<=, a bound: left out) -> median 3; no OIDN speed-up -> a dash.
    def rec(scene, err, ms, speed, bound="="):
        return {**_record(scene, "direct", rel_rmse_8=err), "noise": 0.0, "total_ms": ms,
                "speedup": {"speedup": speed, "bound": bound}, "speedup_oidn": None}

    records = [rec("a", 0.1, 10.0, 2.0), rec("b", 0.3, 30.0, 4.0), rec("c", 0.2, 20.0, 9.0, "<")]
    lines = readme_figures.methods_block(_results(records)).splitlines()
    assert lines[0].startswith("**The methods at a glance**: medians over the 3 scenes")
    assert lines[2:] == ["| method | rel_rmse_8 | noise | ms | speed-up vs Cycles | vs Cycles + OIDN |",
                         "| --- | --- | --- | --- | --- | --- |", "| direct | 0.200 | 0.000 | 20 | 3x | – |"]


def test_octree_block():
    """Each column is the registry row it names (matched exactly), propagation ms sums the transport's
    passes, cell-steps come from `work`, and the summary counts scenes and takes the median time ratio."""
    cols = {title: setting for title, setting in readme_figures.OCTREE_COLUMNS}

    def rec(scene, setting, err, ms, steps, default=False):
        return {**_record(scene, "lpv", default=default, rel_rmse_8=err, bias=0.9), "setting": setting,
                "timings_ms": {"lpv_propagate": ms, "lpv_octree": 1.0, "gbuffer": 50.0},
                "work": {"propagation_cell_steps": steps}}

    records = []
    for scene, grid_err in (("cornell", 0.5), ("thin-wall", 0.2)):
        records += [rec(scene, {"lpv.variant": "improved", "lpv.geometry_volume": True}, 0.38, 99.0, 676_000, True),
                    rec(scene, cols["one grid"], grid_err, 199.0, 3_047_000)]
        records += [rec(scene, setting, 0.4, 9.0, 150_000) for title, setting in readme_figures.OCTREE_COLUMNS[2:]]
    lines = readme_figures.octree_block(_results(records)).splitlines()
    cornell = next(line for line in lines if line.startswith("| cornell"))
    assert cornell == ("| cornell | 0.380 / 0.90, 100 ms, 676k | 0.500 / 0.90, 200 ms, 3047k | "
                       + " | ".join(["0.400 / 0.90, 10 ms, 150k"] * 3) + " |")
    assert lines[-1] == ("- octree, ours (time, its defaults): error at most one grid's on 1 of 2 scenes and at "
                         "most the far field's on 0; propagation time a median 5 % of one grid's.")


def test_headline_block():
    """Per scene the most accurate default indirect record; Cycles' times with their bounds; EEVEE's time
    (of the same run's scene) over ours only where our error is at most EEVEE's, and over the fastest
    default record whose error is."""
    def rec(scene, method, err, ms, cycles_s, bound="="):
        return {**_record(scene, method, rel_rmse_8=err), "product": "indirect", "total_ms": ms,
                "speedup": {"cycles_time_s": cycles_s, "bound": bound, "speedup": 1.0},
                "speedup_oidn": {"cycles_time_s": cycles_s / 2, "bound": bound, "speedup": 1.0}}

    records = [rec("cornell", "lpv", 0.4, 200.0, 0.05), rec("cornell", "vct", 0.13, 750.0, 0.21),
               rec("window-sky", "rsm", 0.9, 100.0, 0.04, "<"),
               {**_record("cornell", "direct"), "product": "direct", "rel_rmse_8": 0.01}]
    results = {**_results(records), "scenes": [
        {"name": "cornell", "eevee": {"time_s": 75.0, "metrics": {"rel_rmse_8": 0.68}}},
        {"name": "window-sky", "eevee": {"time_s": 60.0, "metrics": {"rel_rmse_8": 0.5}}}]}
    lines = readme_figures.headline_block(results).splitlines()
    rows = [line for line in lines if line.startswith("| cornell") or line.startswith("| window-sky")]
    # The fastest within EEVEE's error: on cornell lpv (0.4 <= 0.68, 200 ms; 75 s / 0.2 s = 375x); on
    # window-sky none (0.9 > 0.5).
    assert rows == ["| cornell | vct | 0.130 | 750 ms | 210 ms | 105 ms | 75.0 s at 0.680 | 100x | "
                    "lpv 0.400, 200 ms: 375x |",
                    "| window-sky | rsm | 0.900 | 100 ms | <= 40 ms | <= 20 ms | 60.0 s at 0.500 | "
                    "error above EEVEE's | – |"]


def test_reference_samples_name_the_raised_range():
    results = _results([])
    assert readme_figures._spp(results) == "128 spp"
    results.update(ref_noise=0.03, scenes=[{"ref_spp": 4096}, {"ref_spp": 128}, {"ref_spp": 256}])
    assert readme_figures._spp(results) == \
        "128-4096 spp (raised per scene until two seeds differ by rel_rmse_8 <= 0.03)"


def test_produced_by_says_when_errors_were_measured_again():
    results = _results([])
    assert "measured again" not in readme_figures._produced_by(results)
    results["rescored"] = {"command": "tools/bench_rescore.py --cache C --ref-noise 0.03 --out O", "date": "2026-12-04",
                           "commit": "fedcba9876543210" * 2 + "01234567", "dirty": True}
    assert readme_figures._produced_by(results).endswith(
        " Errors measured again from its cached images by `tools/bench_rescore.py --cache C --ref-noise 0.03 --out O`"
        " on 2026-12-04 (commit fedcba987654 with uncommitted changes).")


def test_choice_block():
    # fit_choice's judged.json summary: one row per budget, the check's time range rounded, and the share
    # of rows whose path-traced estimate is within 1.5x beside the model's.
    budget = {"scenes": 15, "possible": 12, "met": 9, "verified_met": 12, "verified_within_2x": 11,
              "verified_estimate_within_1.5x": 15, "verified_mean_tries": 9.44, "check_time_s": [1.04, 83.6],
              "all_rows_path_traced_within_1.5x": 1.0}
    judged = {"command": ".venv/bin/python tools/fit_choice.py R --cache C",
              "summary": {"0.1": budget, "0.2": {**budget, "check_time_s": None,
                                                 "all_rows_path_traced_within_1.5x": 0.955},
                          "all_rows_estimate_within_1.5x": 0.594}}
    text = readme_figures.choice_block(judged)
    assert "each of the 15 benchmark scenes" in text and "`.venv/bin/python tools/fit_choice.py R --cache C`" in text
    assert "| 0.1 | 12 | 9 | 12 | 11 | 15 | 9.4 | 1.0-84 s |" in text
    assert "| 0.2 | 12 | 9 | 12 | 11 | 15 | 9.4 | – |" in text
    assert "100%, 96% with the check of each budget; the model's own prediction 59%." in text


def test_a_run_older_than_a_methods_defaults_says_so():
    # The recorded config of each method's own group against today's defaults: a changed value is named
    # with its value then, a field the run predates as not yet built, and a run at today's defaults adds
    # nothing.
    from dataclasses import asdict

    from addon.engine.config import DiffusionConfig, LpvConfig

    today = {"diffusion": asdict(DiffusionConfig()), "lpv": asdict(LpvConfig())}
    assert readme_figures._older_line({"lpv": today, "diffusion": today}) == []
    then = {"diffusion": {k: v for k, v in today["diffusion"].items() if k != "far_field"} | {"grid_cells": 16}}
    assert readme_figures._older_line({"diffusion": then, "lpv": today}) == [
        "", "Runs older than today's defaults: diffusion (its settings then: `grid_cells` 16, `far_field` not yet "
            "built)."]
