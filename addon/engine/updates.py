"""The three kinds of update a user makes, timed: what `render --profile-updates`, the benchmark and
tools/gpu_timing.py report as update_ms (Blender-free: any method on any backend)."""

from __future__ import annotations

import statistics
import time
from dataclasses import replace

import numpy as np

UPDATE_STEP_M = 0.01  # how far update_costs moves the lights or the camera per update


def update_costs(method, repeat: int, kinds: tuple[str, ...] = ("full", "lights", "camera")) -> dict[str, float]:
    """Median wall time in ms (GPU work finished, no read-back) of the three kinds of update a user
    makes, each right after its change, alternately moving by UPDATE_STEP_M and back:
    - full: a geometry change, everything: the upload and the setup passes (set_scene: voxelization,
      blocking volumes), the G-buffer, the light views, the solve, the gathers;
    - lights: every light moved UPDATE_STEP_M along z: the light views, the solve and the gathers
      (the G-buffer is still valid);
    - camera: the camera moved UPDATE_STEP_M along its right axis: the G-buffer and the gathers
      (the solve too where the method cannot keep its light field: `keeps_light_field`).
    Only `kinds` of them are timed (a full update of a big scene takes seconds). Per-pass waits are off,
    as in the viewport; the method is left as it was found."""
    be, source, profile = method.backend, method.source, method.profile
    lights, camera = list(source.lights), source.camera
    moved_lights = [replace(light, position_m=light.position_m + np.array([0.0, 0.0, UPDATE_STEP_M]))
                    for light in lights]
    view = camera.view.copy()
    view[0, 3] -= UPDATE_STEP_M  # x in camera space: its right axis
    moved_camera = replace(camera, view=view)

    def timed(update) -> float:
        be.finish()
        t0 = time.perf_counter()
        update()
        be.finish()
        return (time.perf_counter() - t0) * 1e3

    method.profile = False
    samples = {kind: [] for kind in kinds}
    try:
        for i in range(repeat):
            away = i % 2 == 0
            if "full" in kinds:
                samples["full"].append(timed(lambda: (method.set_scene(method.source), method.compute())))
            if "lights" in kinds:
                method.set_lights(moved_lights if away else lights)
                samples["lights"].append(timed(lambda: method.compute(run_gbuffer=False)))
            if "camera" in kinds:
                method.set_camera(moved_camera if away else camera)
                samples["camera"].append(timed(method.compute))
        method.set_lights(lights)
        method.set_camera(camera)
        method.compute()  # the products of the state the caller set
    finally:
        method.profile = profile
    return {kind: statistics.median(ms) for kind, ms in samples.items()}


def update_costs_in_turn(methods: list, rounds: int) -> list[dict[str, float]]:
    """update_costs of several methods set up on one scene, timed in turn: each of `rounds` rounds times
    one update of each kind for every method, and each kind's cost is its median over the rounds.

    A shared machine's load drifts over minutes; timed one method after another, a method timed in a busy
    minute reads slower than one timed in a quiet minute (lpv's light update on the Cornell box read
    100 to 195 ms in runs minutes apart). Taken in turn, the drift falls alike on every method, so the
    ratios between them, which is what a benchmark compares, hold within one run."""
    samples = [{kind: [] for kind in ("full", "lights", "camera")} for _ in methods]
    for _ in range(rounds):
        for method, kinds in zip(methods, samples, strict=True):
            for kind, ms in update_costs(method, 1).items():
                kinds[kind].append(ms)
    return [{kind: statistics.median(ms) for kind, ms in kinds.items()} for kinds in samples]
