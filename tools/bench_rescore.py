"""Measure a finished bench run's errors again against less noisy Cycles references, from the images the
run cached: no method is rendered again.

A Cycles reference at the quick bench's 128 spp carries noise of its own: on window-sky two seeds'
indirect references differ by rel_rmse_8 0.17, so no method can be measured below about 0.12 there, however
right it is. `bench --ref-noise X` raises each scene's reference spp until two seeds differ by at most X;
this applies the same references to a run already made (`bench.rescore`), keeping its times, so a long
run (every registry row on every scene) need not be repeated to be judged against them.

Run: .venv/bin/python tools/bench_rescore.py --cache out/bench-choice --ref-noise 0.03 --out benchmarks/choice/rows
(the cache's bench.json must be the run whose report is in --out: a later bench into the same cache replaces
it, and its runs/ images).
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from addon.bridge import bench  # noqa: E402


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--cache", type=Path, required=True, help="the run's bench cache (holds bench.json)")
    p.add_argument("--ref-noise", type=float, required=True, help="as bench --ref-noise")
    p.add_argument("--out", type=Path, required=True, help="the run's report directory (REPORT.md, results.json)")
    args = p.parse_args(argv)
    result = json.loads((args.cache / "bench.json").read_text())
    if f"--out {args.out}" not in result["command"] and f"--out {args.out.resolve()}" not in result["command"]:
        raise SystemExit(f"{args.cache}/bench.json is the run of `{result['command']}`, not of --out {args.out}")
    bench.rescore(result, args.cache, args.ref_noise)
    result["rescored"]["command"] = (f"tools/bench_rescore.py --cache {args.cache} --ref-noise {args.ref_noise:g} "
                                     f"--out {args.out}")
    report = args.out / "REPORT.md"
    existing = report.read_text() if report.is_file() else None
    report.write_text(bench.merge_report(existing, bench.format_report(result)))
    (args.out / "results.json").write_text(json.dumps(bench.results_json(result), indent=1) + "\n")
    for sc in result["scenes"]:
        if (args.out / sc["plot"]).is_file():
            bench.plot_scene(sc, args.out / sc["plot"])
    (args.cache / "bench.json").write_text(json.dumps(result, indent=2, default=str))
    print(json.dumps({sc["name"]: {"ref_spp": sc["ref_spp"], "noise_floor": {
        p: round(m["rel_rmse_8"], 4) for p, m in sc["noise_floor"].items()}} for sc in result["scenes"]}))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
