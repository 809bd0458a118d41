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

# Known defects of `lpv` at its defaults (improved transport, geometry volume with surface offsets, 32
# cells, far field), measured on llvmpipe, 48 px; "one grid": the figure without the far field; the
# classic variant's figures in brackets. Static and strict, so a fix shows up as XPASS.
LPV = "lpv (improved, geometry volume): "
KNOWN_DEFECTS = {
    "test_one_triangle[lpv]": "indirect 0.12 where the exact answer is 0: the emitter's own VPLs light it "
                              "(one grid 0.11; 0.17 without surface offsets; classic 1.25)",
    "test_km_terrain_under_sun[lpv]": "indirect 0.023 of direct on a flat terrain that cannot light itself "
                                      "(one grid 0.018; 0.0095 without surface offsets; classic 0.23)",
    "test_white_closed_box_conserves_flux[lpv]": "indirect flux 0.88 P in a closed white box (exact P, bound "
                                                 "0.9..1.02): it under-reads (one grid over-read, 1.06: "
                                                 "each step at a wall gains a little; classic 0.80)",
    "test_camera_inside_closed_block[lpv]": "indirect 0.059 inside a closed block: leaks through one-cell walls "
                                            "(one grid 0.058; classic 0.89)",
    "test_light_inside_closed_box_stays_inside[lpv]": "indirect 0.10 x P/(6 pi) outside a closed box: leaks "
                                                      "through walls (one grid 0.096; classic 0.92)",
    "test_two_hundred_lights[lpv]": "indirect 0.018 on geometry that cannot receive a bounce: self-illumination "
                                    "(one grid 0.021; classic 0.15)",
    "test_million_triangle_floor[lpv]": "indirect up to 0.014 on a lone floor that cannot light itself "
                                        "(self-illumination; one grid 0.019; classic: 3e-7 splat-order "
                                        "differences)",
    "test_light_moving_1mm_per_frame[lpv]": "frame-to-frame change 0.011 against 0.007: VPLs change cells "
                                            "as the light moves (grid-aligned popping; one grid 0.0094)",
}


# Known defects of `lpv+classes` (the defaults with LpvConfig.emitter_classes): the five others of the
# list above pass with classes (a surface no longer reads its own light, nor popping above the bound).
CLASSES = "lpv with emitter classes: "
CLASSES_KNOWN_DEFECTS = {
    "test_camera_inside_closed_block[lpv+classes]": "indirect 0.059 inside a closed block: leaks through one-cell "
                                                    "walls (as without classes)",
    "test_white_closed_box_conserves_flux[lpv+classes]": "indirect flux 1.07 P in a closed white box (exact P, "
                                                         "bound 0.9..1.02; 0.88 P without classes): the walls' "
                                                         "own light no longer cancels part of what arrives, and "
                                                         "the L1 transfer's excess at walls shows",
    "test_light_inside_closed_box_stays_inside[lpv+classes]": "indirect 0.14 x P/(6 pi) outside a closed box "
                                                              "(0.10 without classes): light leaked through a "
                                                              "wall facing away read negative there and is now "
                                                              "left out with the receiver's own class",
}

# Known defects of `lpv+octree` (the defaults with LpvConfig.variant = "octree": 4 levels, the time merge,
# k = 12, three blocked levels), measured on llvmpipe, 48 px; lpv's figure in brackets.
OCTREE = "lpv octree: "
OCTREE_KNOWN_DEFECTS = {
    "test_one_triangle[lpv+octree]": "indirect 0.115 where the exact answer is 0: the emitter's own VPLs light it "
                                     "(lpv 0.12)",
    "test_km_terrain_under_sun[lpv+octree]": "indirect 0.018 of direct on a flat terrain that cannot light itself "
                                             "(lpv 0.023)",
    "test_white_closed_box_conserves_flux[lpv+octree]": "indirect flux 0.67 P in a closed white box (exact P, "
                                                        "bound 0.9..1.02; lpv 0.88): it under-reads",
    "test_camera_inside_closed_block[lpv+octree]": "indirect 0.067 inside a closed block: leaks through its walls "
                                                   "(lpv 0.059)",
    "test_light_inside_closed_box_stays_inside[lpv+octree]": "indirect 0.11 x P/(6 pi) outside a closed box: "
                                                             "leaks through walls (lpv 0.10)",
    "test_thin_wall_between_rooms[lpv+octree]": "dark room's mean indirect 0.011 of the lit room's mean direct "
                                                "(bound 0.01; lpv passes): coarse cells straddle the shared wall, "
                                                "and the levels above octree_blocked_levels do not block",
    "test_two_hundred_lights[lpv+octree]": "indirect 0.015 on geometry that cannot receive a bounce: "
                                           "self-illumination (lpv 0.018)",
    "test_million_triangle_floor[lpv+octree]": "indirect up to 0.021 on a lone floor that cannot light itself "
                                               "(self-illumination; lpv 0.023)",
    "test_light_moving_1mm_per_frame[lpv+octree]": "frame-to-frame change 0.014 against 0.007: VPLs change cells "
                                                   "as the light moves, on every level (lpv 0.011)",
}

# Known defects of `vct` (defaults: 64 cells, 16 cones), measured on llvmpipe, 48 px. A voxel holds
# both faces of a wall thinner than a cell, and a cone passing near it reads the far face's light.
VCT = "vct: "
VCT_KNOWN_DEFECTS = {
    "test_camera_inside_closed_block[vct]": "indirect up to 0.095 inside a closed block (exact 0): its walls are "
                                            "one cell thick, so their lit outer faces share voxels with the inner "
                                            "faces the cones pass",
    "test_light_inside_closed_box_stays_inside[vct]": "indirect outside up to 0.22 x P/(6 pi) (exact 0): the box's "
                                                      "one-cell walls hold its lit inner faces with their exact, "
                                                      "partial opacity",
}

# Known defects of `diffusion` (defaults: cone fields without emitter classes, 32 cells, 2 x the longest
# side steps per bounce, far field), measured on llvmpipe, 48 px (docs/DIFFUSION.md, "Measured limits").
# A plane's light in the cones beside its normal partly falls back onto it: a cone's L1 fit of the lobe
# is positive a little below the plane's horizon. A closed shape smaller than two cells has no empty
# inside for its inner faces' light, and a wall of zero thickness shares its cells with both rooms.
DIFFUSION = "diffusion: "
DIFFUSION_KNOWN_DEFECTS = {
    "test_one_triangle[diffusion]": "indirect 0.023 where the exact answer is 0: the plane's own light falls back "
                                    "onto it (the emitter classes, off by default, keep it off)",
    "test_million_triangle_floor[diffusion]": "indirect 0.0033 on a lone floor (exact 0), its own light as in "
                                              "test_one_triangle; the floor and its quarter read the same to fp32 "
                                              "rounding",
    "test_km_terrain_under_sun[diffusion]": "indirect 0.0064 on a flat terrain (bound 1e-6 of its direct, 0.61): its "
                                            "own light, as in test_one_triangle",
    "test_two_hundred_lights[diffusion]": "indirect 0.0032 on a lone plane (exact 0): its own light, as in "
                                          "test_one_triangle",
    "test_thin_wall_between_rooms[diffusion]": "indirect in the dark room 0.015 of the lit room's mean direct "
                                               "(bound 0.01), as the single field's",
    "test_light_inside_closed_box_stays_inside[diffusion]": "indirect 0.14 x P/(6 pi) outside a closed box (exact "
                                                            "0; the single field 0.049): the 1 m box spans 3 cells, "
                                                            "none of them empty, so its inner faces' light leaves "
                                                            "by the cells' outer faces",
    "test_camera_inside_closed_block[diffusion]": "indirect 9.5e-8 inside a closed block (exact 0): the far field "
                                                  "shares light that reached its outer face onto an inner one, as "
                                                  "the single field's (5.4e-12)",
    "test_white_closed_box_conserves_flux[diffusion+cells16]": "indirect flux 1.047 P in a closed white box at 16 "
                                                               "cells (exact P, bound 0.9..1.02; 0.952 P at 32): "
                                                               "the half cells along the edges no light reaches "
                                                               "read their neighbours' flux / area, which holds "
                                                               "the strips' light too (docs/DIFFUSION.md, "
                                                               "'Coarse grids over-read near edges')",
}

# Known defects of `probes` (defaults: 16 probes a side, 8^2 texels a face, Chebyshev visibility),
# measured on llvmpipe, 48 px (docs/PROBES.md, "Measured").
PROBES = "probes: "
PROBES_KNOWN_DEFECTS = {
    "test_camera_inside_closed_block[probes]": "indirect 0.13 inside a closed block (exact 0) at an inner corner: "
                                               "the receiver lies 2 mm behind the wall an outside probe sees it "
                                               "through, below what 8^2-texel distance moments resolve",
    "test_light_inside_closed_box_stays_inside[probes]": "indirect 0.002 x P/(6 pi) outside a closed box (exact "
                                                         "0): texels of the box's outer faces at its edges see "
                                                         "its lit inside past the shared edge (rasterization)",
}


# Known defects of `gather` (the probes' defaults, 4 x 4 quads a face), measured on llvmpipe, 48 px
# (docs/GATHER.md, "Limits"). It reads the probes' captures, so it inherits their defects; near the
# offending texels its form factors make them count more than the probes' SH does.
GATHER = "gather: "
GATHER_KNOWN_DEFECTS = {
    "test_camera_inside_closed_block[gather]": "indirect 0.072 inside a closed block (exact 0): the probes' "
                                               "visibility lets an outside probe through (as for `probes`, "
                                               "0.13), and its quads then light the inner corner",
    "test_light_inside_closed_box_stays_inside[gather]": "indirect 0.049 x P/(6 pi) outside a closed box (exact "
                                                         "0): the probes' texels at the box's outer edges that "
                                                         "see its lit inside (`probes`: 0.002) become quad "
                                                         "lights beside the ground",
}


# Known defects of diffusion's single field with emitter classes in place of its cone fields
# ("diffusion+classes": DiffusionConfig(cone_fields=False, emitter_class_passes=True), the directional
# transfer), measured on llvmpipe, 48 px (docs/DIFFUSION.md, "Measured limits").
SINGLE = "diffusion+classes: "
SINGLE_KNOWN_DEFECTS = {
    "test_thin_wall_between_rooms[diffusion+classes]": "indirect in the dark room 0.015 of the lit room's mean "
                                                       "direct (bound 0.01): it passed (0) while the lookup read "
                                                       "every occupied side; skipping the sides no light can "
                                                       "reach lets some light of the lit side through (path not "
                                                       "isolated)",
    "test_light_inside_closed_box_stays_inside[diffusion+classes]": "indirect 0.049 x P/(6 pi) outside a closed box "
                                                                    "(exact 0): the 1 m box spans 3 cells, none of "
                                                                    "them empty, so its inner faces' light leaves "
                                                                    "by the cells' outer faces",
    "test_camera_inside_closed_block[diffusion+classes]": "indirect 5.4e-12 inside a closed block (exact 0): the far "
                                                          "field shares a far cell's light over the fine cells "
                                                          "within one far cell of it, and the 0.6 m block spans 1.5 "
                                                          "far cells, so light that reached its outer face lands "
                                                          "on an inner one (docs/DIFFUSION.md, 'Far field')",
}

_DEFECTS = ((LPV, KNOWN_DEFECTS), (CLASSES, CLASSES_KNOWN_DEFECTS), (OCTREE, OCTREE_KNOWN_DEFECTS),
            (VCT, VCT_KNOWN_DEFECTS), (DIFFUSION, DIFFUSION_KNOWN_DEFECTS), (SINGLE, SINGLE_KNOWN_DEFECTS),
            (PROBES, PROBES_KNOWN_DEFECTS), (GATHER, GATHER_KNOWN_DEFECTS))


def pytest_collection_modifyitems(items):
    for item in items:
        for prefix, defects in _DEFECTS:
            reason = defects.get(item.name)
            if reason is not None:
                item.add_marker(pytest.mark.xfail(strict=True, reason=prefix + reason))


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
