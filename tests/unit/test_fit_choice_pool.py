"""tools/fit_choice.py pools several bench runs: a later run's row replaces an earlier's of the same
scene, method and setting, and every other row is kept."""

import importlib.util
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]


def _fit_choice():
    spec = importlib.util.spec_from_file_location("fit_choice", ROOT / "tools" / "fit_choice.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def row(scene, method, cells, error, ms, product="indirect"):
    return {"scene": scene, "method": method, "setting": {"lpv.grid_cells": cells}, "rel_rmse_8": error,
            "total_ms": ms, "product": product}


def test_a_later_run_replaces_its_rows_and_keeps_the_others():
    fit_choice = _fit_choice()
    first = {"records": [row("a", "lpv", 16, 0.3, 10.0), row("a", "lpv", 32, 0.2, 20.0),
                         row("b", "lpv", 16, 0.4, 11.0), row("a", "direct", 16, 0.01, 5.0, product="direct")]}
    rerun = {"records": [row("a", "lpv", 32, 0.25, 15.0), row("c", "vct", 16, 0.1, 30.0)]}
    pooled = fit_choice.pooled([first, rerun])
    # a's 32-cell row is the re-run's, in its place; b and a's 16-cell row stay; c is added; the direct
    # row is judged on no bounce and left out (records_of)
    assert [(r["scene"], r["method"], r["setting"]["lpv.grid_cells"], r["rel_rmse_8"]) for r in pooled] == [
        ("a", "lpv", 16, 0.3), ("a", "lpv", 32, 0.25), ("b", "lpv", 16, 0.4), ("c", "vct", 16, 0.1)]
    assert pooled[1]["total_ms"] == 15.0
