"""Scene builders and a method runner shared by the hard-case tests (tests/hard).

Every scene is built in code: axis-aligned boxes and rectangles with per-corner normals, per-triangle
albedo, Cycles-unit lights and a square perspective camera.
"""

from __future__ import annotations

import numpy as np
import pytest

from addon.engine import methods
from addon.engine.config import METHODS, DiffusionConfig, GIConfig, LpvConfig, RsmConfig, VctConfig
from addon.engine.scene import Camera, Light, Scene
from addon.engine.transforms import look_along, perspective

# Every shipped method; a later method joins the suite by joining config.METHODS.
# Every method, rsm with its voxel visibility, lpv with emitter classes (LpvConfig.emitter_classes),
# lpv's octree variant (LpvConfig.variant = "octree") and diffusion's single field with emitter classes
# in place of its cone fields (DiffusionConfig.emitter_class_passes, cone_fields).
ALL_METHODS = (*METHODS, "rsm+voxel", "lpv+classes", "lpv+octree", "diffusion+classes")

# rsm without visibility lets one bounce through walls: a known property of the method (its
# `--visibility voxel` option is the fix), marked here once so every leak test says so the same way.
NO_VISIBILITY = ("rsm gathers VPLs without visibility (RsmConfig.visibility = 'none'), so bounce light "
                 "passes walls")


def methods_with_known_leaks(voxel_reason: str | None = None):
    """ALL_METHODS for leak tests, the no-visibility gather marked as a strict expected failure, and the
    voxel-visibility gather too where `voxel_reason` says why its grid cannot resolve the case."""
    reasons = {"rsm": NO_VISIBILITY, "rsm+voxel": voxel_reason}
    return [pytest.param(m, marks=pytest.mark.xfail(strict=True, reason=reasons[m])) if reasons.get(m) else m
            for m in ALL_METHODS]


def rect(origin, u, v):
    """Two triangles of the parallelogram origin + [0,1] u + [0,1] v; normal u x v (normalised)."""
    o, u, v = (np.asarray(a, np.float64) for a in (origin, u, v))
    p = [o, o + u, o + u + v, o + v]
    n = np.cross(u, v)
    n = n / np.linalg.norm(n)
    return np.array([[p[0], p[1], p[2]], [p[0], p[2], p[3]]]), np.array([[n] * 3] * 2)


def box(lo, hi, inward=True):
    """The six faces of an axis-aligned box (12 triangles), normals pointing in (or out)."""
    lo, hi = np.asarray(lo, np.float64), np.asarray(hi, np.float64)
    d = hi - lo
    ex, ey, ez = np.diag(d)
    faces = [
        rect(lo, ey, ex),            # z = lo, normal +z (inward)
        rect(lo + ez, ex, ey),       # z = hi, normal -z
        rect(lo, ex, ez),            # y = lo, normal +y
        rect(lo + ey, ez, ex),       # y = hi, normal -y
        rect(lo, ez, ey),            # x = lo, normal +x
        rect(lo + ex, ey, ez),       # x = hi, normal -x
    ]
    tris = np.concatenate([f[0] for f in faces])
    nrm = np.concatenate([f[1] for f in faces])
    return tris, (nrm if inward else -nrm)


def parts(*pieces):
    """Concatenate (triangles, normals, albedo) pieces; albedo is a float or an RGB triple per piece."""
    tris, nrms, albs = [], [], []
    for t, n, a in pieces:
        tris.append(t)
        nrms.append(n)
        albs.append(np.broadcast_to(np.asarray(a, np.float64), (len(t), 3)))
    return np.concatenate(tris), np.concatenate(nrms), np.concatenate(albs)


def camera(eye, forward, size=48, fov_deg=70.0, near=None, far=None, up=(0, 0, 1)):
    eye = np.asarray(eye, np.float64)
    scale = max(float(np.linalg.norm(eye)), 1.0)
    near = 1e-3 * scale if near is None else near
    far = 1e3 * scale if far is None else far
    return Camera(look_along(eye, forward, np.asarray(up, np.float64)), perspective(np.radians(fov_deg), near, far),
                  size, size)


def scene(geometry, lights, cam) -> Scene:
    tris, nrm, alb = geometry
    n = len(tris)
    return Scene(np.asarray(tris, np.float32).reshape(n, 3, 3), np.asarray(nrm, np.float32).reshape(n, 3, 3),
                 np.asarray(alb, np.float32).reshape(n, 3), np.zeros((n, 3), np.float32), list(lights),
                 camera=cam)


def empty_scene(lights, cam) -> Scene:
    return Scene(lights=list(lights), camera=cam)


def point(pos, power, color=(1, 1, 1)):
    return Light("POINT", pos, [0, 0, -1], color, power_w=float(power))


def sun(direction, strength, color=(1, 1, 1)):
    return Light("SUN", [0, 0, 0], direction, color, sun_strength=float(strength))


def make(gl, name, rsm_res=128, vpl=64):
    """A method by name; "rsm+voxel" is the rsm method with voxel-traced visibility, "lpv+classes" lpv
    with emitter classes, "lpv+octree" lpv's octree variant, "vct+filtered" vct with filtered injection,
    "diffusion+cellsN" diffusion on a grid of N cells, "diffusion+classes" diffusion's single field with
    emitter classes."""
    method, _, variant = name.partition("+")
    kw = {"resolution": rsm_res, "vpl_samples": vpl}
    if variant == "classes" and method == "diffusion":
        return methods.create(gl, {"gi": GIConfig(method=method), "rsm": RsmConfig(**kw),
                                   "diffusion": DiffusionConfig(cone_fields=False, emitter_class_passes=True)})
    if variant == "classes":
        return methods.create(gl, {"gi": GIConfig(method=method), "rsm": RsmConfig(**kw),
                                   "lpv": LpvConfig(emitter_classes=True)})
    if variant == "octree":
        return methods.create(gl, {"gi": GIConfig(method=method), "rsm": RsmConfig(**kw),
                                   "lpv": LpvConfig(variant="octree")})
    if variant.startswith("cells"):
        return methods.create(gl, {"gi": GIConfig(method=method), "rsm": RsmConfig(**kw),
                                   "diffusion": DiffusionConfig(grid_cells=int(variant[len("cells"):]))})
    if variant == "filtered":
        return methods.create(gl, {"gi": GIConfig(method=method), "rsm": RsmConfig(**kw),
                                   "vct": VctConfig(filtered_injection=True)})
    if variant:
        kw["visibility"] = variant
    return methods.get(method)(gl, GIConfig(method=method), RsmConfig(**kw))


def render(gl, name, sc, rsm_res=128, vpl=64) -> dict[str, np.ndarray]:
    """Run `name` once on `sc`; returns its images (h, w, 4) float32, row 0 = top."""
    m = make(gl, name, rsm_res, vpl)
    m.set_scene(sc)
    return m.run().images


def lit(images) -> np.ndarray:
    """Direct + indirect RGB (indirect absent for `direct`)."""
    out = images["direct"][..., :3].astype(np.float64)
    if "indirect" in images:
        out = out + images["indirect"][..., :3]
    return out


def assert_sane(images):
    """Every product finite and non-negative (alpha included)."""
    for key, img in images.items():
        bad = ~np.isfinite(img)
        assert not bad.any(), f"{key}: {int(bad.sum())} non-finite values"
        assert img.min() >= 0.0, f"{key}: min {img.min():g} < 0"


def products(images):
    """The light products a method returned (direct, and indirect where it has one)."""
    return {k: v for k, v in images.items() if k in ("direct", "indirect")}


def room_with_a_roof_opening(hole_m):
    """A closed 2 x 2 x 1.5 m room (zero-thickness faces) whose roof has a square opening of side
    `hole_m` at its centre: the four roof strips around it, and the opening's outline."""
    a, h = 0.5 * hole_m, 1.5
    roof = [rect([-1, -1, h], [2, 0, 0], [0, 1 - a, 0]), rect([-1, a, h], [2, 0, 0], [0, 1 - a, 0]),
            rect([-1, -a, h], [1 - a, 0, 0], [0, 2 * a, 0]), rect([a, -a, h], [1 - a, 0, 0], [0, 2 * a, 0])]
    walls = [rect([-1, -1, 0], [0, 2, 0], [2, 0, 0]), rect([-1, -1, 0], [2, 0, 0], [0, 0, h]),
             rect([-1, 1, 0], [0, 0, h], [2, 0, 0]), rect([-1, -1, 0], [0, 0, h], [0, 2, 0]),
             rect([1, -1, 0], [0, 2, 0], [0, 0, h])]
    geometry = parts(*[(t, n, 0.5) for t, n in roof + walls])
    outline = np.array([[-a, -a, h], [a, -a, h], [a, a, h], [-a, a, h]])
    return geometry, outline


def room(s=1.0, offset=(0.0, 0.0, 0.0), albedo=0.7):
    """An open-top room [-1, 1]^2 x [0, 2] (x s, + offset) with a block [-.3, .3]^2 x [0, .5] on its floor
    casting shadows, walls tinted so the bounce carries colour."""
    o = np.asarray(offset, np.float64)
    walls, wn = box(np.array([-1, -1, 0]) * s + o, np.array([1, 1, 2]) * s + o)
    walls, wn = walls[np.r_[0:2, 4:12]], wn[np.r_[0:2, 4:12]]  # drop the ceiling (triangles 2, 3)
    blk, bn = box(np.array([-0.3, -0.3, 0.0]) * s + o, np.array([0.3, 0.3, 0.5]) * s + o, inward=False)
    wall_albedo = np.full((len(walls), 3), albedo)
    wall_albedo[6:8] = [albedo, 0.2, 0.2]   # x = lo wall red
    wall_albedo[8:10] = [0.2, albedo, 0.2]  # x = hi wall green
    return (np.concatenate([walls, blk]), np.concatenate([wn, bn]),
            np.concatenate([wall_albedo, np.full((len(blk), 3), 0.8)]))


def room_camera(s=1.0, offset=(0.0, 0.0, 0.0), size=48):
    o = np.asarray(offset, np.float64)
    eye = np.array([0.9, -0.95, 1.7]) * s + o
    target = np.array([-0.3, 0.3, 0.2]) * s + o
    return Camera(look_along(eye, target - eye), perspective(np.radians(75), 0.01 * s, 20.0 * s), size, size)


ROOM_LIGHT_M = np.array([0.4, 0.5, 1.4])


# Figures recorded by the tests (conftest.figures) for docs/HARD_CASES.md.

def allclose_figure(actual, desired, rtol, atol=0.0) -> float:
    """The relative error np.testing.assert_allclose(actual, desired, rtol, atol) measures: the smallest rtol
    at which it passes, max |a - d| / (|d| + atol / rtol), so the assert holds iff this is <= rtol."""
    a, d = np.asarray(actual, np.float64), np.asarray(desired, np.float64)
    diff = np.abs(a - d)
    with np.errstate(divide="ignore", invalid="ignore"):
        err = np.where(diff == 0, 0.0, diff / (np.abs(d) + atol / rtol))  # 0 / 0 where equal counts as exact
    return float(err.max()) if err.size else 0.0


def sanity(images) -> str:
    """What assert_sane checks, as a figure: 'finite, min 0' or the count of non-finite values."""
    bad = sum(int((~np.isfinite(img)).sum()) for img in images.values())
    if bad:
        return f"{bad} non-finite"
    return f"finite, min {min(float(img.min()) for img in images.values()):.3g}"


POLE_HALF_M = 0.025  # pole_room's pole: 5 cm square


def pole_room():
    """A closed 2 m room lit by a 200 W lamp, a 5 cm pole (1.3 px) standing before its back wall, seen
    at 64 px from the front: a thin detail whose pixels the denoise filter has little of their surface
    to average with (passes/surface_support.py). pole_indirect renders it and finds its pixels."""
    h = POLE_HALF_M
    geometry = parts((*box([-1, -1, 0], [1, 1, 2]), 0.7), (*box([-h, 0.5, 0], [h, 0.5 + 2 * h, 2], inward=False), 0.7))
    return scene(geometry, [point([0.3, -0.3, 1.8], 200.0)], camera([0, -0.95, 1.0], [0, 1, 0], size=64, fov_deg=80))


def pole_indirect(backend, settings: dict, seed: int):
    """pole_room's indirect (row 0 = top) with `settings` ({group: config}, the method in gi's), at 64 px,
    unfiltered (GIConfig.denoise off), and the pole's pixels (from the G-buffer's world positions)."""
    from dataclasses import replace

    from addon.engine import methods

    method = methods.create(backend, {**settings, "gi": replace(settings["gi"], resolution=64, seed=seed,
                                                                   denoise=False)})
    method.set_scene(pole_room())
    indirect = method.run().images["indirect"][..., :3]
    position = backend.read(method.gbuf["position"])[::-1] + np.append(method.origin_m, 0.0)
    pole = (np.abs(position[..., 0]) < POLE_HALF_M + 1e-3) & (position[..., 1] < 0.5 + 2 * POLE_HALF_M + 1e-3)
    return indirect, pole & (position[..., 3] > 0)


def assert_only_the_pole_changes(one, more, pole) -> None:
    """Two pole_room images, one and more samples where the filter finds little surface
    (passes/surface_support.py): 81 % of the pole's pixels change (those at its foot and head find the
    floor's and ceiling's; bound 70 %), 3.3 % of the image in all (a few more at the image's corners;
    bound 10 %: the walls stay bit for bit)."""
    changed = np.any(one != more, axis=-1)
    print("changed share:", changed.mean(), "pole pixels:", pole.sum(), "changed on the pole:", changed[pole].mean())
    assert pole.sum() >= 20 and changed[pole].mean() > 0.7
    assert changed.mean() < 0.1
