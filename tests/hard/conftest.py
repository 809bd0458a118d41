"""tests/hard: the helpers module `hard_scenes` sits beside the tests (no package: importlib mode).

It also records every test's measured figures (the `figures` fixture) so that
`tools/hard_cases_report.py` can tabulate case, bound and figure per method in docs/HARD_CASES.md.
Records are written only when BOUNCE_HARD_FIGURES names a file; an ordinary run keeps nothing.
"""

from __future__ import annotations

import datetime
import json
import math
import os
import platform
import shlex
import sys
from pathlib import Path

import pytest

HERE = str(Path(__file__).resolve().parent)
if HERE not in sys.path:
    sys.path.insert(0, HERE)

# Module-level rather than in a session fixture: the outcomes come from the report hook and are only
# final after the last test's teardown, so the file is written in pytest_sessionfinish.
_RECORDS: list[dict] = []
_OUTCOMES: dict[str, str] = {}
_META: dict[str, str] = {}


@pytest.fixture
def figures(request, gl_backend):
    """`figures(case, method, figure, bound)` records one measured figure of this test.

    Call it BEFORE the assertion on that figure, so failing and xfail cases keep their real number.
    The node's static xfail mark (and reason) is stored with it: the report marks those cells.
    (Every hard test renders with `gl`, so asking for gl_backend here costs nothing and names the renderer.)
    """
    _META.setdefault("renderer", gl_backend.renderer)
    mark = request.node.get_closest_marker("xfail")

    def record(case: str, method: str, figure: float | str, bound: str) -> None:
        if not isinstance(figure, str):
            figure = float(figure)  # numpy scalars -> float
            # JSON has no portable NaN/inf literal: such figures are kept as strings ("nan", "inf").
            figure = figure if math.isfinite(figure) else str(figure)
        _RECORDS.append({
            "test": request.node.originalname, "nodeid": request.node.nodeid, "case": case, "method": method,
            "figure": figure,
            "bound": bound, "xfail": mark.kwargs.get("reason", "xfail") if mark else None,
        })

    return record


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_makereport(item, call):
    # The cell shows how the test ended (passed / failed / xfailed / xpassed / skipped): the worst phase wins.
    report = (yield).get_result()
    if report.when == "call" or report.outcome != "passed":
        outcome = ("xfailed" if report.skipped else "xpassed") if hasattr(report, "wasxfail") else report.outcome
        _OUTCOMES[item.nodeid] = outcome


def pytest_sessionfinish(session, exitstatus):
    path = os.environ.get("BOUNCE_HARD_FIGURES")
    if not path or not _RECORDS:
        return
    # The machine that measured the figures (the report may be rendered elsewhere).
    meta = {"command": shlex.join(["pytest", *sys.argv[1:]]),
            "date": datetime.datetime.now().astimezone().isoformat(timespec="seconds"),
            "platform": platform.platform(), "python": platform.python_version(), "cpu": _cpu_model(),
            "cpus": os.cpu_count(), **_META}
    records = [{**r, "outcome": _OUTCOMES.get(r["nodeid"], "unknown")} for r in _RECORDS]
    Path(path).parent.mkdir(parents=True, exist_ok=True)
    # Every test's outcome too, so the report can name tests that recorded nothing (skipped ones, say).
    Path(path).write_text(json.dumps({"meta": meta, "records": records, "outcomes": _OUTCOMES}, indent=1) + "\n")


def _cpu_model() -> str:
    try:
        lines = Path("/proc/cpuinfo").read_text().splitlines()
    except OSError:  # not Linux
        return platform.processor()
    return next((ln.split(":", 1)[1].strip() for ln in lines if ln.startswith("model name")), platform.processor())
