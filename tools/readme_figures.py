"""Rewrite the generated figure blocks of README.md and docs/ from the benchmarks' results.json files.

    .venv/bin/python tools/readme_figures.py            # rewrite the blocks (README.md, docs/LPV.md)
    .venv/bin/python tools/readme_figures.py --check    # exit 1 if a block differs from its results.json

A block is the text between `<!-- figures:NAME:begin -->` and `<!-- figures:NAME:end -->`; everything
outside the markers is left as it is. Each block is a function of one results.json (written by
`python -m addon bench` beside its REPORT.md), so a README figure cannot drift from the run it quotes:
tests/unit/test_readme_figures.py fails when a block was edited by hand or its results.json changed.
A table at the methods' defaults also reads today's defaults (addon/engine/config.py): a run older than a
change of them names the settings it ran with, so the check fails until the block is rewritten.
"""

from __future__ import annotations

import argparse
import json
import re
import sys
from collections.abc import Callable
from dataclasses import asdict
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from addon.engine.config import GROUPS  # noqa: E402

README = ROOT / "README.md"
UPDATES_JSON = ROOT / "benchmarks" / "updates" / "results.json"
DEFAULTS_JSON = ROOT / "benchmarks" / "defaults" / "results.json"
LPV_DOC = ROOT / "docs" / "LPV.md"
OCTREE_JSON = ROOT / "benchmarks" / "octree" / "results.json"
DIFFUSION_DOC = ROOT / "docs" / "DIFFUSION.md"
PROBES_DOC = ROOT / "docs" / "PROBES.md"
# every probes row ran in the choice model's run (all methods' registry rows on all 15 scenes)
PROBES_JSON = ROOT / "benchmarks" / "choice" / "rows" / "results.json"
# The GPU runs (tools/gpu_timing.py on a lent GPU; benchmarks/gpu/REPORT.md), in order: a later run's
# figure for a (scene, setting) replaces an earlier one's.
GPU_JSON = tuple(ROOT / "benchmarks" / "gpu" / f"h200-{run}.json" for run in ("timings", "rows", "denoise"))
GPU_SCENES = ("cornell", "window-sky", "sponza")
DIFFUSION_JSON = (ROOT / "benchmarks" / "diffusion" / "b1" / "results.json",
                  ROOT / "benchmarks" / "diffusion" / "b2" / "results.json")
# tools/fit_choice.py's held-out judgement of the choice for an error budget (benchmarks/choice/REPORT.md)
CHOICE_JSON = ROOT / "benchmarks" / "choice" / "judged.json"
LPV_CAMERA_TARGET_PCT = 15  # the target: lpv's camera update <= 15 % of its full update
_BLOCK = re.compile(r"(<!-- figures:(?P<name>[a-z0-9-]+):begin -->\n)(?P<body>.*?)(<!-- figures:(?P=name):end -->)",
                    re.S)


def load(path: Path) -> dict:
    return json.loads(path.read_text())


def _seconds(s: float) -> str:
    return f"{1e3 * s:.0f} ms" if s < 1 else f"{s:.1f} s"


def _produced_by(results: dict) -> str:
    """Two lines: the command, then when, where and on which code (markdown joins them)."""
    m = results["machine"]
    code = f"commit {m['commit'][:12]}" + (" with uncommitted changes" if m["dirty"] else "")
    start, end = m["load_average_1min"]  # timings shared the cores with whatever else ran
    rescored = results.get("rescored")
    again = (f" Errors measured again from its cached images by `{rescored['command']}` on {rescored['date']} "
             f"(commit {rescored['commit'][:12]}{' with uncommitted changes' if rescored['dirty'] else ''}).") \
        if rescored else ""
    return (f"Produced by `{results['command']}`\n"
            f"on {m['date']} ({code}; {m['cpu']}, {m['cores']} cores, load average {start:.1f} / {end:.1f} at the "
            f"start / end; {m['bounce_renderer']}; Blender {m['blender']}).{again}")


def _spp(results: dict) -> str:
    """The run's reference samples: one count, or with `--ref-noise` each scene's range and the floor."""
    if results.get("ref_noise") is None:
        return f"{results['ref_spp']} spp"
    spps = sorted({sc["ref_spp"] for sc in results["scenes"]})
    return (f"{spps[0]}-{spps[-1]} spp (raised per scene until two seeds differ by rel_rmse_8 <= "
            f"{results['ref_noise']:g})")


def _older_defaults(method: str, config: dict) -> list[str]:
    """The fields of `method`'s own settings group (config.GROUPS) whose value in a run's recorded
    `config` ({group: {field: value}}) is not today's default, or which the run predates: a table that
    says "at its defaults" names them, so a run older than a change of defaults cannot pass for a new one."""
    if method not in GROUPS:
        return []
    recorded = config.get(method, {})
    return [name for name, value in asdict(GROUPS[method]()).items() if name not in recorded or recorded[name] != value]


def _older_line(configs: dict[str, dict]) -> list[str]:
    """["", a sentence naming, per method, the fields _older_defaults finds in its recorded config
    ({method: config}) and their values then ("not yet built" where the run predates the field)], or []."""
    older = {m: _older_defaults(m, c) for m, c in configs.items()}
    if not any(older.values()):
        return []

    def then(m, f):
        return json.dumps(configs[m][m][f]) if f in configs[m].get(m, {}) else "not yet built"

    return ["", "Runs older than today's defaults: " + "; ".join(
        f"{m} (its settings then: " + ", ".join(f"`{f}` {then(m, f)}" for f in fields) + ")"
        for m, fields in older.items() if fields) + "."]


def _older_records(records: list[dict]) -> list[str]:
    """_older_line of the methods' recorded configs in a run's default records."""
    return _older_line({r["method"]: r["config"] for r in records if "config" in r})


def _default_records(results: dict) -> list[dict]:
    """Each method's record at its default settings, in the run's order."""
    return [r for r in results["records"] if r["default"]]


def _methods(records: list[dict]) -> list[str]:
    return list(dict.fromkeys(r["method"] for r in records))


def _camera_pct(update_ms: dict) -> float:
    return 100 * update_ms["camera"] / update_ms["full"]


def update_costs_block(results: dict) -> str:
    """Table: full / lights / camera update ms per scene and method at its defaults, camera as a
    percentage of full; then lpv's ratio against the issue's target."""
    records = _default_records(results)
    lines = ["**Update costs** of each method at its default settings.", "",
             _produced_by(results) + f" Medians of {results['repeat']} updates of each kind; full = a geometry "
             "change (the upload, the setup passes and everything after), lights = every light moved 1 cm, camera = "
             "the camera moved 1 cm. A scene's methods are timed in turn in one process, one update of each kind per "
             "round, so the machine's changing load falls alike on all of them.", "",
             "| scene | size | method | full ms | lights ms | camera ms | camera / full |",
             "| --- | --- | --- | --- | --- | --- | --- |"]
    for r in records:
        u = r["update_ms"]
        w, h = r["image_size"]
        lines.append(f"| {r['scene']} | {w} x {h} | {r['method']} | {u['full']:.1f} | {u['lights']:.1f} | "
                     f"{u['camera']:.1f} | {_camera_pct(u):.0f} % |")
    lpv = [r for r in records if r["method"] == "lpv"]
    if lpv:
        ratios = ", ".join(f"{_camera_pct(r['update_ms']):.1f} % on {r['scene']}" for r in lpv)
        met = all(_camera_pct(r["update_ms"]) <= LPV_CAMERA_TARGET_PCT for r in lpv)
        lines += ["", f"lpv's camera update costs {ratios} of its full update (target <= {LPV_CAMERA_TARGET_PCT} %: "
                      f"{'met' if met else 'not met'})."]
    # The probes issue's target: a light update no slower than lpv's in the same run.
    lights = {(r["scene"], r["method"]): r["update_ms"]["lights"] for r in records}
    pairs = [(scene, ms, lights[(scene, "lpv")]) for (scene, method), ms in lights.items()
             if method == "probes" and (scene, "lpv") in lights]
    if pairs:
        ratios = ", ".join(f"{100 * ms / lpv_ms:.0f} % on {scene}" for scene, ms, lpv_ms in pairs)
        met = all(ms <= lpv_ms for _, ms, lpv_ms in pairs)
        lines += ["", f"probes' light update costs {ratios} of lpv's (target <= 100 %: {'met' if met else 'not met'})."]
    lines += _older_records(records)
    return "\n".join(lines) + "\n"


def _speedup(s: dict | None) -> str:
    """A speed-up with the bound of metrics.cycles_equivalent_speedup: '<=' our error is above Cycles'
    fastest point (at most this), '>=' below its slowest (at least this); '–' where undefined."""
    if s is None or s["speedup"] is None:
        return "–"
    return {"=": "", "<": "<= ", ">": ">= "}[s["bound"]] + f"{s['speedup']:.3g}x"


def accuracy_block(results: dict) -> str:
    """Table: each method's rel_rmse_8 / bias at its defaults on every scene of the run, and its speed-up
    against Cycles + OIDN where the run measured that anchor (results.json schema 2 on)."""
    records = _default_records(results)
    methods = _methods(records)
    by_key = {(r["scene"], r["method"]): r for r in records}
    oidn = any(r.get("speedup_oidn") for r in records)
    lines = ["**Accuracy against Cycles** of each method at its default settings.", "",
             _produced_by(results) + f" {results['res']} px long side, Cycles reference {_spp(results)}; "
             "cells: rel_rmse_8 / bias" + (" / speed-up against Cycles + OIDN" if oidn else "")
             + " (direct against Cycles' Diffuse Direct, the others against Diffuse Indirect"
             + ("; speed-up = the time Cycles with Open Image Denoise needs for the same rel_rmse_8 / ours, <= and "
                ">= where our error lies outside its curve" if oidn else "") + ").",
             "", "| scene | " + " | ".join(methods) + " |", "| --- " * (1 + len(methods)) + "|"]
    for scene in dict.fromkeys(r["scene"] for r in records):
        cells = []
        for method in methods:
            r = by_key.get((scene, method))
            if r is None or r["rel_rmse_8"] is None:
                cells.append("–")
                continue
            cell = f"{r['rel_rmse_8']:.3f} / {r['bias']:.3f}"
            cells.append(cell + f" / {_speedup(r['speedup_oidn'])}" if oidn else cell)
        lines.append(f"| {scene} | " + " | ".join(cells) + " |")
    lines += _older_records(records)
    return "\n".join(lines) + "\n"


def _median(values: list[float]) -> float | None:
    values = sorted(v for v in values if v is not None)
    if not values:
        return None
    mid = len(values) // 2
    return values[mid] if len(values) % 2 else (values[mid - 1] + values[mid]) / 2


def methods_block(results: dict) -> str:
    """Table: per method at its defaults, the medians over the run's scenes of its error (rel_rmse_8),
    its own noise (seed against seed), its update time, and its speed-ups against Cycles and against
    Cycles + OIDN (undefined speed-ups, where our error lies outside a curve, left out of the median)."""
    records = _default_records(results)
    scenes = list(dict.fromkeys(r["scene"] for r in records))

    def speed(r, key):
        s = r.get(key)
        return s["speedup"] if s and s["bound"] == "=" else None

    lines = ["**The methods at a glance**: medians over the " + f"{len(scenes)} scenes of the run below "
             "(rel_rmse_8 and noise of the light each method makes, against Cycles' Diffuse Indirect, or Direct for "
             "`direct`; time of one full update on the run's machine; speed-up = the time Cycles needs for the "
             "same rel_rmse_8 / ours, where our error lies on its curve).", "",
             "| method | rel_rmse_8 | noise | ms | speed-up vs Cycles | vs Cycles + OIDN |",
             "| --- | --- | --- | --- | --- | --- |"]
    for method in _methods(records):
        rows = [r for r in records if r["method"] == method]
        err, noise = _median([r["rel_rmse_8"] for r in rows]), _median([r.get("noise") for r in rows])
        ms = _median([r["total_ms"] for r in rows])
        raw, oidn = _median([speed(r, "speedup") for r in rows]), _median([speed(r, "speedup_oidn") for r in rows])

        def f(x, fmt):
            return "–" if x is None else fmt.format(x)

        lines.append(f"| {method} | {f(err, '{:.3f}')} | {f(noise, '{:.3f}')} | {f(ms, '{:.0f}')} | "
                     f"{f(raw, '{:.2g}x')} | {f(oidn, '{:.2g}x')} |")
    lines += _older_records(records)
    return "\n".join(lines) + "\n"


def _cycles_time(s: dict | None) -> str:
    """Cycles' time to our rel_rmse_8 along its curve, with the bound of metrics.cycles_equivalent_speedup
    ('<=': our error is above its fastest point; '>=': below its slowest)."""
    if s is None or s.get("cycles_time_s") is None:
        return "–"
    return {"=": "", "<": "<= ", ">": ">= "}[s["bound"]] + _seconds(s["cycles_time_s"])


def headline_block(results: dict) -> str:
    """Table: per scene, our most accurate method at its defaults (indirect light) with its time, and what
    the anchors of the same run need for the same rel_rmse_8: raw Cycles and Cycles + OIDN along their
    curves, and EEVEE's render at its best GI setting (its time and error, since an EEVEE render is not a
    curve; `bench --anchors oidn,eevee`)."""
    eevee = {sc["name"]: sc.get("eevee") for sc in results["scenes"]}
    records = [r for r in _default_records(results) if r["product"] == "indirect" and r["rel_rmse_8"] is not None]
    lines = ["**Our time at equal error**: per scene, the most accurate method at its defaults and what the "
             "anchors need to match it.", "",
             "Ours and Cycles (raw, and with Open Image Denoise: the time Cycles needs for the same rel_rmse_8 along "
             "its curve of the same run; <= where our error is above its fastest point). " + _produced_by(results)
             + f" {results['res']} px long side, indirect light against Cycles at {_spp(results)}.", "",
             "EEVEE: one render per scene at its best GI setting in the same run, its time and rel_rmse_8 against "
             "the same reference; EEVEE / ours = its time over ours where our error is at most its own; fastest "
             "within EEVEE's error: of our methods at their defaults, the fastest whose error is at most EEVEE's, "
             "and EEVEE's time over its.", "",
             "| scene | method | rel_rmse_8 | ours | Cycles | Cycles + OIDN | EEVEE | EEVEE / ours | "
             "fastest within EEVEE's error |",
             "| --- | --- | --- | --- | --- | --- | --- | --- | --- |"]
    for scene in dict.fromkeys(r["scene"] for r in records):
        best = min((r for r in records if r["scene"] == scene), key=lambda r: r["rel_rmse_8"])
        ev = eevee.get(scene)
        ev_err = ev["metrics"]["rel_rmse_8"] if ev else None
        ev_cell = f"{_seconds(ev['time_s'])} at {ev_err:.3f}" if ev and ev_err is not None else "–"
        as_good = [r for r in records if r["scene"] == scene and ev_err is not None and r["rel_rmse_8"] <= ev_err]
        fastest = min(as_good, key=lambda r: r["total_ms"]) if as_good else None
        fast_cell = (f"{fastest['method']} {fastest['rel_rmse_8']:.3f}, {_seconds(fastest['total_ms'] / 1e3)}: "
                     f"{ev['time_s'] / (fastest['total_ms'] / 1e3):.3g}x") if fastest else "–"
        if ev_err is None:
            ratio = "–"
        elif best["rel_rmse_8"] <= ev_err:
            ratio = f"{ev['time_s'] / (best['total_ms'] / 1e3):.3g}x"
        else:
            ratio = "error above EEVEE's"
        lines.append(f"| {scene} | {best['method']} | {best['rel_rmse_8']:.3f} | {_seconds(best['total_ms'] / 1e3)} "
                     f"| {_cycles_time(best['speedup'])} | {_cycles_time(best.get('speedup_oidn'))} | {ev_cell} | "
                     f"{ratio} | {fast_cell} |")
    lines += _older_records(records)
    return "\n".join(lines) + "\n"


# The octree table's columns: each a registry benchmark row of lpv (registry.METHODS), matched exactly.
OCTREE_COLUMNS = (
    ("far field (default)", None),
    ("one grid", {"lpv.variant": "improved", "lpv.geometry_volume": True, "lpv.far_field": False}),
    ("octree, paper (index, eps -> 0, 5 levels blocked, k = 4)",
     {"lpv.variant": "octree", "lpv.octree_merge": "index", "lpv.octree_levels": 5, "lpv.octree_iterations": 4,
      "lpv.octree_epsilon": 1e-6, "lpv.octree_blocked_levels": 5}),
    ("octree, index (eps 0.5, 3 blocked, k = 4)",
     {"lpv.variant": "octree", "lpv.octree_merge": "index", "lpv.octree_levels": 5, "lpv.octree_iterations": 4}),
    ("octree, ours (time, its defaults)", {"lpv.variant": "octree"}),
)
# The passes that move light through the grids (the far field's add and the octree's merges included).
PROPAGATION_PASSES = ("lpv_inflow", "lpv_propagate", "lpv_far_field", "lpv_octree")


def _propagation_ms(record: dict) -> float:
    return sum(record["timings_ms"].get(k, 0.0) for k in PROPAGATION_PASSES)


def pick(records: list[dict], scene: str, method: str, setting: dict | None) -> dict | None:
    """The record of `method` on `scene` at the registry row `setting` (None: the method's defaults)."""
    return next((r for r in records if r["scene"] == scene and r["method"] == method
                 and (r["default"] if setting is None else r["setting"] == setting)), None)


def octree_block(results: dict) -> str:
    """Table: per scene, lpv's far field (its default), one grid and the three octree rows side by side:
    rel_rmse_8 / bias, propagation ms and cell-steps (results.json `work`); then, per octree row, on how
    many scenes it beats one grid and the far field, and its propagation time against one grid's."""
    lpv = [r for r in results["records"] if r["method"] == "lpv"]

    scenes = list(dict.fromkeys(r["scene"] for r in lpv))
    lines = ["**lpv: the octree against the far field and one grid.**", "",
             _produced_by(results) + f" {results['res']} px long side, Cycles reference {_spp(results)}, "
             f"one bounce. Cells: rel_rmse_8 / bias, propagation ms (the passes {', '.join(PROPAGATION_PASSES)}; "
             f"medians of {results['repeat']} updates), cell-steps in thousands (cells x steps over every grid "
             "and level).", "",
             "| scene | " + " | ".join(title for title, _ in OCTREE_COLUMNS) + " |",
             "| --- " * (1 + len(OCTREE_COLUMNS)) + "|"]
    for scene in scenes:
        cells = []
        for _, setting in OCTREE_COLUMNS:
            r = pick(lpv, scene, "lpv", setting)
            if r is None or r["rel_rmse_8"] is None:
                cells.append("–")
                continue
            steps = r.get("work", {}).get("propagation_cell_steps")
            cells.append(f"{r['rel_rmse_8']:.3f} / {r['bias']:.2f}, {_propagation_ms(r):.0f} ms"
                         + (f", {steps / 1e3:.0f}k" if steps is not None else ""))
        lines.append(f"| {scene} | " + " | ".join(cells) + " |")
    lines.append("")
    for title, setting in OCTREE_COLUMNS[2:]:
        pairs = [(pick(lpv, s, "lpv", setting), pick(lpv, s, "lpv", OCTREE_COLUMNS[1][1]), pick(lpv, s, "lpv", None))
                 for s in scenes]
        pairs = [(o, g, f) for o, g, f in pairs if o and g and f and None not in
                 (o["rel_rmse_8"], g["rel_rmse_8"], f["rel_rmse_8"])]
        if not pairs:
            continue
        below_grid = sum(o["rel_rmse_8"] <= g["rel_rmse_8"] for o, g, _ in pairs)
        below_far = sum(o["rel_rmse_8"] <= f["rel_rmse_8"] for o, _, f in pairs)
        ratio = _median([_propagation_ms(o) / _propagation_ms(g) for o, g, _ in pairs if _propagation_ms(g) > 0])
        lines.append(f"- {title}: error at most one grid's on {below_grid} of {len(pairs)} scenes and at most the "
                     f"far field's on {below_far}; propagation time a median {100 * ratio:.0f} % of one grid's.")
    return "\n".join(lines) + "\n"


# The side-by-side grids: per method, its registry rows at 16, 32 (the defaults) and 64 cells.
GRID_COLUMNS = (
    ("lpv", {"lpv.variant": "improved", "lpv.geometry_volume": True, "lpv.grid_cells": 16}, 16),
    ("lpv", None, 32),
    ("lpv", {"lpv.variant": "improved", "lpv.geometry_volume": True, "lpv.grid_cells": 64}, 64),
    ("diffusion", {"diffusion.grid_cells": 16}, 16),
    ("diffusion", None, 32),
    ("diffusion", {"diffusion.grid_cells": 64}, 64),
)


def diffusion_block(*runs: dict) -> str:
    """Table: per scene and bounce count (one results.json per bounce count), lpv and diffusion at
    16, 32 and 64 cells: rel_rmse_8 and the benchmark's ms; then, per grid and bounce count, on how
    many scenes diffusion's error is at most lpv's, and its time against lpv's (median ratio); the default
    cone fields' error against the single field's, and the paper's cone transfer's against the directional
    one's."""
    lines = ["**diffusion beside lpv, grids of 16, 32 and 64 cells.**", ""]
    lines += [_produced_by(run) + f" {run['res']} px long side, {run['bounces']} bounce(s), Cycles reference "
              f"{_spp(run)}." for run in runs]
    lines += ["", "Cells: rel_rmse_8 against Cycles' Diffuse Indirect, the benchmark's time (ms: the median of its "
              "updates after a warm-up; both on the run's machine, ratios only).", "",
              "| scene | bounces | " + " | ".join(f"{m} {c}" for m, _, c in GRID_COLUMNS) + " |",
              "| --- " * (2 + len(GRID_COLUMNS)) + "|"]
    for run in runs:
        records = run["records"]
        for scene in dict.fromkeys(r["scene"] for r in records):
            cells = []
            for method, setting, _ in GRID_COLUMNS:
                r = pick(records, scene, method, setting)
                missing = r is None or r["rel_rmse_8"] is None
                cells.append("–" if missing else f"{r['rel_rmse_8']:.3f}, {r['total_ms']:.0f}")
            lines.append(f"| {scene} | {run['bounces']} | " + " | ".join(cells) + " |")
    lines.append("")
    for run in runs:
        records = run["records"]
        scenes = list(dict.fromkeys(r["scene"] for r in records))
        parts = []
        for (_, lpv_setting, cells), (_, diff_setting, _) in zip(GRID_COLUMNS[:3], GRID_COLUMNS[3:], strict=True):
            pairs = [(s, pick(records, s, "diffusion", diff_setting), pick(records, s, "lpv", lpv_setting))
                     for s in scenes]
            pairs = [(s, d, lp) for s, d, lp in pairs if d and lp and d["rel_rmse_8"] is not None
                     and lp["rel_rmse_8"] is not None]
            if not pairs:
                continue
            wins = [s for s, d, lp in pairs if d["rel_rmse_8"] <= lp["rel_rmse_8"]]
            ratio = _median([d["total_ms"] / lp["total_ms"] for _, d, lp in pairs])
            parts.append(f"at {cells} cells on {len(wins)} of {len(pairs)} scenes"
                         + (f" ({', '.join(wins)})" if wins else "") + f", in {ratio:.2f}x lpv's time")
        lines.append(f"- {run['bounces']} bounce(s): diffusion's error is at most lpv's " + "; ".join(parts) + ".")
        single = {"diffusion.cone_fields": False, "diffusion.emitter_class_passes": True}
        for ours, theirs, what in ((None, single, "the cone fields (32 cells, the defaults) have a median {:.2f}x "
                                                  "the single field's (with its emitter classes) error"),
                                   ({**single, "diffusion.transfer": "cone"}, single,
                                    "the paper's cone transfer (32 cells, the single field) has a median {:.2f}x the "
                                    "directional transfer's error")):
            pairs = [(pick(records, s, "diffusion", ours), pick(records, s, "diffusion", theirs)) for s in scenes]
            ratios = [a["rel_rmse_8"] / b["rel_rmse_8"] for a, b in pairs
                      if a and b and a["rel_rmse_8"] is not None and b["rel_rmse_8"]]
            if ratios:
                lines.append(f"- {run['bounces']} bounce(s): " + what.format(_median(ratios))
                             + f", below it on {sum(r < 1 for r in ratios)} of {len(ratios)} scenes.")
    return "\n".join(lines) + "\n"


def encodings_block(results: dict) -> str:
    """Table: per scene, probes with the SH encoding (its defaults) and the irradiance encoding:
    rel_rmse_8 / bias and the benchmark's ms; then on how many scenes each is the more accurate."""
    probes = [r for r in results["records"] if r["method"] == "probes"]

    irradiance = {"probes.encoding": "irradiance"}
    lines = ["**probes: the two encodings.**", "",
             _produced_by(results) + f" {results['res']} px long side, {results['bounces']} bounce(s), Cycles "
             f"reference {_spp(results)}. Cells: rel_rmse_8 / bias against Cycles' Diffuse Indirect, "
             "the benchmark's time (ms: the median of its updates after a warm-up, on the run's machine).", "",
             "| scene | SH (default) | irradiance |", "| --- | --- | --- |"]
    better = total = 0
    for scene in dict.fromkeys(r["scene"] for r in probes):
        pair = [pick(probes, scene, "probes", None), pick(probes, scene, "probes", irradiance)]
        cells = ["–" if r is None or r["rel_rmse_8"] is None
                 else f"{r['rel_rmse_8']:.3f} / {r['bias']:.3f}, {r['total_ms']:.0f}" for r in pair]
        lines.append(f"| {scene} | " + " | ".join(cells) + " |")
        if all(r is not None and r["rel_rmse_8"] is not None for r in pair):
            total += 1
            better += pair[1]["rel_rmse_8"] < pair[0]["rel_rmse_8"]
    lines += ["", f"The irradiance encoding is the more accurate on {better} of {total} scenes."]
    return "\n".join(lines) + "\n"


def gpu_block(*runs: dict) -> str:
    """Table: each method's light and camera updates at its defaults on a GPU at 1920 x 1080, per scene;
    then the denoise filter's share of vct's update (the issue's target). The runs' geometry changes
    are left out: their set-up re-made every camera-sized image then (REPORT.md)."""
    configs: dict[tuple[str, str], dict] = {}
    for run in runs:
        for scene, entry in run["scenes"].items():
            for label, result in entry["configs"].items():
                if "error" not in result:
                    configs[(scene, label)] = result
    last = runs[-1]
    w, h = last["size"]
    methods = list(dict.fromkeys(label for (_, label) in configs if "-" not in label))
    lines = [f"**On a GPU** ({last['renderer'].split(' / ')[1].split('/')[0]}, OpenGL through EGL, no Blender: the "
             f"scenes captured here and timed there by `tools/gpu_timing.py`; {w} x {h}; medians of "
             f"{last['repeat']} updates of each kind; `benchmarks/gpu/REPORT.md` gives the runs and their code). "
             "ms per update: every light moved 1 cm / the camera moved 1 cm.", "",
             "| method | " + " | ".join(GPU_SCENES) + " |", "| --- |" + " --- |" * len(GPU_SCENES)]
    for method in methods:
        cells = []
        for scene in GPU_SCENES:
            u = configs.get((scene, method), {}).get("update_ms")
            cells.append("–" if u is None else f"{u['lights']:.1f} / {u['camera']:.1f}")
        lines.append(f"| {method} | " + " | ".join(cells) + " |")
    lines += _older_line({m: next(r["config"] for (_, label), r in configs.items() if label == m) for m in methods})
    shares = [(s, configs[(s, "vct")]) for s in GPU_SCENES if (s, "vct") in configs]
    if shares:
        lines += ["", "vct's denoise filter (GPU time) costs " + ", ".join(
            f"{100 * r['gpu']['denoise']['median'] / r['wall_total']['median']:.0f} % on {s}" for s, r in shares)
            + " of its update (target <= 20 %), three products on every scene in that run; cornell and window-sky"
            " now filter two (docs/ARCHITECTURE.md, \"A clean preview\")."]
    return "\n".join(lines) + "\n"


def choice_block(judged: dict) -> str:
    """Table: per error budget, what `render --method auto --error-budget E` (verified: candidates judged
    by the path-traced check, the default) and with `--no-verify` (the model alone) met on held-out
    scenes, from fit_choice's judged.json (its summary)."""
    s = judged["summary"]
    budgets = [b for b in s if b.replace(".", "", 1).isdigit()]
    lines = ["**Choosing for an error budget, and saying how far from a path tracer**: each of the "
             f"{s[budgets[0]]['scenes']} benchmark scenes judged by a model fitted without it "
             "(`benchmarks/choice/REPORT.md`, from `" + judged["command"] + "`). `render --method auto "
             "--error-budget E` renders candidate settings fastest first and judges each against two "
             "few-sample Cycles renders of the scene, their own noise subtracted (`bake` judges lightmaps "
             "likewise on the largest objects; `--no-verify` takes the model's choice unchecked; "
             "`--self-check` reports the same estimate for any render, `bake --self-check` for each "
             "lightmap).", "",
             "| E | scenes where some setting meets E | met, the model alone | met, verified | verified within 2x "
             "of the fastest setting meeting E | its estimate within 1.5x of the error | settings tried | "
             "the Cycles check (128 px) |",
             "| --- | --- | --- | --- | --- | --- | --- | --- |"]
    for b in budgets:
        v = s[b]
        t = v.get("check_time_s")
        lines.append(f"| {b} | {v['possible']} | {v['met']} | {v['verified_met']} | {v['verified_within_2x']} | "
                     f"{v['verified_estimate_within_1.5x']} | {v['verified_mean_tries']:.1f} | "
                     + (f"{t[0]:.1f}-{t[1]:.0f} s" if t else "–") + " |")
    shares = ", ".join(f"{s[b]['all_rows_path_traced_within_1.5x']:.0%}" for b in budgets
                       if "all_rows_path_traced_within_1.5x" in s[b])
    lines += ["", f"Every benchmark row's estimate within a factor 1.5 of its measured error: {shares} with the "
              f"check of each budget; the model's own prediction {s['all_rows_estimate_within_1.5x']:.0%}."]
    return "\n".join(lines) + "\n"


# block name -> (the file it is in, its results.json file(s), the function that formats them)
BLOCKS: dict[str, tuple[Path, tuple[Path, ...], Callable[..., str]]] = {
    "headline": (README, (DEFAULTS_JSON,), headline_block),
    "update-costs": (README, (UPDATES_JSON,), update_costs_block),
    "gpu": (README, GPU_JSON, gpu_block),
    "accuracy": (README, (DEFAULTS_JSON,), accuracy_block),
    "methods": (README, (DEFAULTS_JSON,), methods_block),
    "choice": (README, (CHOICE_JSON,), choice_block),
    "lpv-octree": (LPV_DOC, (OCTREE_JSON,), octree_block),
    "diffusion-grids": (DIFFUSION_DOC, DIFFUSION_JSON, diffusion_block),
    "probes-encodings": (PROBES_DOC, (PROBES_JSON,), encodings_block),
}


def documents() -> list[Path]:
    """The files that hold generated blocks."""
    return list(dict.fromkeys(doc for doc, _, _ in BLOCKS.values()))


def render_blocks(doc: Path = README) -> dict[str, str]:
    """The bodies of `doc`'s blocks, from their results.json files."""
    return {name: fmt(*map(load, paths)) for name, (where, paths, fmt) in BLOCKS.items() if where == doc}


def rewrite(text: str, blocks: dict[str, str]) -> str:
    """`text` with the body of every block named in `blocks` replaced; a named block missing from the
    text is an error (an edit removed its markers)."""
    missing = set(blocks) - {m["name"] for m in _BLOCK.finditer(text)}
    if missing:
        raise ValueError(f"the text has no markers for block(s): {', '.join(sorted(missing))}")
    return _BLOCK.sub(lambda m: m[1] + blocks.get(m["name"], m["body"]) + m[4], text)


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--check", action="store_true", help="exit 1 if a generated block is not up to date")
    args = p.parse_args(argv)
    stale = []
    for doc in documents():
        text = doc.read_text()
        new = rewrite(text, render_blocks(doc))
        if new != text:
            stale.append(doc)
            if not args.check:
                doc.write_text(new)
    if args.check and stale:
        names = ", ".join(str(d.relative_to(ROOT)) for d in stale)
        print(f"{names}: figure blocks differ from benchmarks' results.json: run tools/readme_figures.py",
              file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
