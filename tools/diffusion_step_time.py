"""One `diffusion` propagation step (both transfers, and one cone field's: DiffusionConfig.cone_fields) against
one `lpv` step (improved, geometry volume: its defaults), on
the same backend in the same run, on a grid of N^3 cells a third of which hold surfaces (docs/DIFFUSION.md,
"Speed"). Each figure: the median over the rounds of (32 steps, finish()) / 32, alternating the methods so
all see the same load; wall-clock ms and the process's CPU ms (llvmpipe runs the shaders on this
process's threads, so its CPU time is the work done, which other processes on a shared machine move much
less than the wall clock), and each against lpv's. Where the context has GL timestamp queries, also the
GPU time: the sum over the steps of a timestamp pair around each step's dispatch, which leaves out the
gaps in which the GPU waits for Python to submit the next step (on a real GPU a 32^3 step's work is
shorter than its submission, so only this figure compares the shaders).

Run: .venv/bin/python tools/diffusion_step_time.py [--cells 32] [--rounds 5]
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
sys.path.insert(0, str(Path(__file__).resolve().parent))

from gpu_timing import GpuTimestamps  # noqa: E402

from addon.engine.backends.moderngl_backend import ModernGLBackend  # noqa: E402
from addon.engine.grid import Grid  # noqa: E402
from addon.engine.passes import diffusion_cells, diffusion_propagate, lpv_propagate  # noqa: E402

STEPS = 32


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cells", type=int, default=32)
    parser.add_argument("--rounds", type=int, default=5)
    args = parser.parse_args()
    n, rounds = args.cells, args.rounds
    be = ModernGLBackend()
    grid = Grid(np.zeros(3), 0.1, (n, n, n))
    rng = np.random.default_rng(0)
    shape = (n, n, n, 4)
    occupied = rng.random((n, n, n)) < 0.33
    voxels = {
        "vox_albedo": np.where(occupied[..., None], [0.5, 0.5, 0.5, 1.0], 0.0).astype(np.float32),
        "vox_normal": np.where(occupied[..., None], [0.0, 0.0, 1.0, 1.0], 0.0).astype(np.float32),
        "vox_projected": np.where(occupied[..., None], [0.2, 0.3, 1.0, 1.0], 0.0).astype(np.float32),
        "vox_offset": np.zeros(shape, np.float32),
    }
    vox = {k: be.texture(grid.dims, "RGBA32F", v) for k, v in voxels.items()}
    cells = diffusion_cells.textures(be, grid)
    diffusion_cells.run(be, vox, cells, grid)
    blocking = lpv_propagate.blocking(be, vox, grid, True)
    field = [rng.random(shape).astype(np.float32) for _ in range(3)]
    sets = [{f"sh_{c}": be.texture(grid.dims, "RGBA32F", f) for c, f in zip("rgb", field, strict=True)}
            for _ in range(2)]
    absorbed = diffusion_propagate.sides(be, grid)
    acc = {f"acc_{c}": be.texture(grid.dims) for c in "rgb"}

    stamps = GpuTimestamps()
    if stamps.available:
        be.ctx.__enter__()  # keep the context current so the queries land in the backend's context

    def stamped(step):
        if not stamps.available:
            return step()
        with stamps.timed({}, "step"):
            step()

    def diffusion(transfer, cone=None):
        def steps():
            for i in range(STEPS):
                stamped(lambda i=i: diffusion_propagate.run(be, sets[i % 2], sets[(i + 1) % 2], absorbed, cells, grid,
                                                            i == 0, transfer, cone))
        return steps

    def lpv():
        for i in range(STEPS):
            stamped(lambda i=i: lpv_propagate.run(be, sets[i % 2], sets[(i + 1) % 2], acc, grid, "improved", i == 0,
                                                  blocking))

    runs = {"diffusion (cone)": diffusion("cone"), "diffusion (directional)": diffusion("directional"),
            "diffusion (a cone field's)": diffusion("directional", cone=4), "lpv": lpv}
    wall = {name: [] for name in runs}
    cpu = {name: [] for name in runs}
    gpu = {name: [] for name in runs}
    for round_ in range(rounds + 1):  # the first round compiles and warms up
        for name, steps in runs.items():
            be.finish()
            if stamps.available:
                stamps.begin_update()
            t0, c0 = time.perf_counter(), time.process_time()
            steps()
            be.finish()
            if round_:
                wall[name].append((time.perf_counter() - t0) * 1e3 / STEPS)
                cpu[name].append((time.process_time() - c0) * 1e3 / STEPS)
                if stamps.available:
                    gpu[name].append(stamps.end_update()["step"] / STEPS)
    for name in runs:
        w, c = statistics.median(wall[name]), statistics.median(cpu[name])
        line = (f"{name}: {w:.3f} ms per step at {n}^3 ({w / statistics.median(wall['lpv']):.2f}x lpv), "
                f"{c:.3f} CPU ms ({c / statistics.median(cpu['lpv']):.2f}x lpv)")
        if stamps.available:
            g = statistics.median(gpu[name])
            line += f", {g:.4f} GPU ms ({g / statistics.median(gpu['lpv']):.2f}x lpv)"
        print(f"{line} (median of {rounds} x {STEPS} steps)")
    print("renderer:", be.renderer)


if __name__ == "__main__":
    main()
