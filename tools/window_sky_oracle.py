"""Where the sky pass's error on window-sky comes from: the direct light computed with exact visibility
through the window, at three levels of the sky pass's model, each against Cycles (docs/DIRECT.md, "What
limits the sky pass").

    .venv/bin/python tools/window_sky_oracle.py SCENE.blend REFERENCE_DIR [--res 128] [--counts 186 744]

SCENE.blend is window-sky or window-sky-sun (`python -m addon scene NAME`): a closed room whose one
opening is the north wall's window, a tunnel through the wall, so a ray from inside sees the sky exactly
when it passes both of the tunnel's ends. REFERENCE_DIR holds Cycles' `direct.exr` of the same camera and
size. Each pixel's surface point and normal come from Blender's ray cast through the pixel's centre; the
world is the map Bounce captures (bridge/world_capture.py), each texel sampled at SUB x SUB directions.

- map: the sum over the map's texels of L cos V dw (exact visibility): what the map alone allows;
- regions, exact fraction: each of `count` regions (world.world_suns, as the sky pass splits them) as
  its sun (|V_R| along V_R) times the share of its light the point sees, that share exact: the sky
  pass's model with a perfect shadow filter;
- regions, hard: each region's light from its one direction, visibility exact there;
- regions, T taps: each region's visible share from T exact rays over it (world.region_taps), as the
  sky pass estimates it;
- with --jitter, regions, T parts jittered: each of a region's T parts (world.region_parts) from one
  direction per pixel drawn uniformly over it, with that direction's radiance, cosine and visibility
  (an unbiased estimate), at seeds 0 and 1: its error and its noise between the seeds.
The suns (the scene's SUN lamps, the sky's captured disc) are added with exact visibility to each.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from addon.engine import world  # noqa: E402  (after the path: the tool runs from anywhere)

SUB = 4  # directions per map texel and side
PIXEL_CHUNK = 128  # pixels per visibility batch (memory: chunk x directions booleans)


def surface_points(scene, res: int) -> tuple[np.ndarray, np.ndarray, tuple[int, int]]:
    """(h * w, 3) points and normals facing the camera of each pixel centre's first hit, rows top down,
    and (h, w)."""
    import bpy

    depsgraph = bpy.context.evaluated_depsgraph_get()
    cam = scene.camera
    aspect = scene.render.resolution_x / scene.render.resolution_y
    w, h = (res, round(res / aspect)) if aspect >= 1 else (round(res * aspect), res)
    top_right, bottom_right, bottom_left, top_left = (cam.matrix_world @ v for v in cam.data.view_frame(scene=scene))
    origin = cam.matrix_world.translation
    points, normals = np.zeros((h * w, 3)), np.zeros((h * w, 3))
    for i in range(h):
        for j in range(w):
            u, v = (j + 0.5) / w, (i + 0.5) / h
            d = (top_left.lerp(top_right, u).lerp(bottom_left.lerp(bottom_right, u), v) - origin).normalized()
            hit, location, normal, *_ = scene.ray_cast(depsgraph, origin, d)
            if not hit:
                raise SystemExit(f"pixel ({i}, {j}) sees no geometry: not a closed room")
            points[i * w + j] = location
            normals[i * w + j] = normal if normal.dot(d) < 0 else -normal
    return points, normals, (h, w)


def window_tunnel(scene) -> tuple[float, float, tuple, tuple]:
    """The north wall's opening: its inner and outer y and its x and z ranges, from the wall's parts."""
    from mathutils import Vector

    def box(name):
        corners = np.array([scene.objects[name].matrix_world @ Vector(c) for c in scene.objects[name].bound_box])
        return corners.min(axis=0), corners.max(axis=0)

    (left_lo, left_hi), (right_lo, _) = box("NorthWall.Left"), box("NorthWall.Right")
    (_, below_hi), (above_lo, _) = box("NorthWall.Below"), box("NorthWall.Above")
    return left_lo[1], left_hi[1], (left_hi[0], right_lo[0]), (below_hi[2], above_lo[2])


def sees_sky(points: np.ndarray, towards: np.ndarray, tunnel) -> np.ndarray:
    """(points, directions) booleans: the ray leaves the room through both ends of the window's tunnel."""
    return leaves_room(points[:, None, :], towards[None, :, :], tunnel)


def leaves_room(points: np.ndarray, towards: np.ndarray, tunnel) -> np.ndarray:
    """Booleans over the broadcast shape of points and towards (..., 3): each ray passes both ends of
    the window's tunnel."""
    y_in, y_out, (x0, x1), (z0, z1) = tunnel
    dy = np.where(towards[..., 1] > 1e-9, towards[..., 1], np.nan)
    out = np.ones(np.broadcast_shapes(points.shape, towards.shape)[:-1], bool)
    for y in (y_in, y_out):
        t = (y - points[..., 1]) / dy
        x = points[..., 0] + t * towards[..., 0]
        z = points[..., 2] + t * towards[..., 2]
        out &= (t > 0) & (x >= x0) & (x <= x1) & (z >= z0) & (z <= z1)
    return out


def jittered_sky(points, normals, radiance, parts, tunnel, seed: int) -> np.ndarray:
    """(points, 3) irradiance from one direction per pixel and part, uniform in solid angle over the
    part's rectangle of the map (independent per pixel), weighted by its texel's radiance, its own
    cosine and exact visibility: an unbiased estimate of int L cos V dw over the parts."""
    h, w = radiance.shape[:2]
    rng = np.random.default_rng(seed)
    e = np.zeros((len(points), 3))
    for rows, cols in parts:
        z_lo, z_hi = np.sin(np.pi / 2 - np.pi * rows.stop / h), np.sin(np.pi / 2 - np.pi * rows.start / h)
        lon_lo, lon_hi = 2 * np.pi * cols.start / w - np.pi, 2 * np.pi * cols.stop / w - np.pi
        u = rng.random((len(points), 2))
        z, lon = z_lo + u[:, 0] * (z_hi - z_lo), lon_lo + u[:, 1] * (lon_hi - lon_lo)
        ring = np.sqrt(np.maximum(1 - z * z, 0))
        toward = np.stack([ring * np.cos(lon), ring * np.sin(lon), z], axis=1)
        row = np.clip(((np.pi / 2 - np.arcsin(z)) / np.pi * h).astype(int), rows.start, rows.stop - 1)
        col = np.clip(((lon + np.pi) / (2 * np.pi) * w).astype(int), cols.start, cols.stop - 1)
        weight = (z_hi - z_lo) * (lon_hi - lon_lo) * np.maximum(np.sum(normals * toward, axis=1), 0)
        e += radiance[row, col] * (weight * leaves_room(points, toward, tunnel))[:, None]
    return e


def sub_directions(h: int, w: int):
    """SUB x SUB directions per map texel that look north (+y: the only way out): unit vectors, solid
    angles (world.directions of the SUB-times finer map) and their texel's flat index."""
    towards, omega = world.directions(h * SUB, w * SUB)
    texel = np.arange(h * SUB)[:, None] // SUB * w + np.arange(w * SUB)[None, :] // SUB
    keep = towards[..., 1].ravel() > 1e-6
    return towards.reshape(-1, 3)[keep], omega.ravel()[keep], texel.ravel()[keep]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("blend")
    ap.add_argument("reference")
    ap.add_argument("--res", type=int, default=128)
    ap.add_argument("--counts", type=int, nargs="+", default=[186, 744])
    ap.add_argument("--taps", type=int, nargs="*", default=[4, 8, 16])
    ap.add_argument("--jitter", action="store_true",
                    help="also each region's T parts from one jittered direction per pixel (seeds 0 and 1)")
    args = ap.parse_args()

    import bpy
    from mathutils import Vector

    from addon.bridge import world_capture
    from addon.bridge.images import read_exr
    from addon.engine import metrics

    bpy.ops.wm.open_mainfile(filepath=str(Path(args.blend).resolve()))
    scene = bpy.context.scene
    points, normals, size = surface_points(scene, args.res)
    tunnel = window_tunnel(scene)
    captured = world_capture.capture(scene.world)
    radiance = np.asarray(captured.map, np.float64)
    h, w = radiance.shape[:2]
    towards, omega, texel = sub_directions(h, w)
    texel_radiance = radiance.reshape(-1, 3)[texel]

    suns = [(np.asarray(o.matrix_world.to_3x3() @ Vector((0, 0, 1))),
             o.data.energy * np.asarray(o.data.color)) for o in scene.objects if o.type == "LIGHT"
            and o.data.type == "SUN"]
    suns += [(-s.direction, s.sun_strength * s.color) for s in captured.suns]
    sun_e = np.zeros((len(points), 3))
    for toward, irradiance in suns:
        toward = toward / np.linalg.norm(toward)
        sun_e += (np.maximum(normals @ toward, 0) * sees_sky(points, toward[None], tunnel)[:, 0])[:, None] * irradiance

    reference = read_exr(Path(args.reference) / "direct.exr")[..., :3]

    def image(sky_e: np.ndarray) -> np.ndarray:
        return ((sky_e + sun_e) / np.pi).reshape(*size, 3)

    def report(label: str, sky_e: np.ndarray) -> None:
        print(f"{label}: rel_rmse_8 {metrics.rel_rmse_8(image(sky_e), reference):.4f}, "
              f"bias {metrics.bias(image(sky_e), reference):.4f}")

    exact = np.zeros((len(points), 3))
    for a in range(0, len(points), PIXEL_CHUNK):
        cos = np.maximum(normals[a:a + PIXEL_CHUNK] @ towards.T, 0)
        exact[a:a + PIXEL_CHUNK] = (cos * sees_sky(points[a:a + PIXEL_CHUNK], towards, tunnel) * omega) @ texel_radiance
    report(f"map {h} x {w}, exact visibility", exact)

    _, solid_angle = world.directions(h, w)
    power = (radiance @ world.LUMA) * solid_angle
    weight = (texel_radiance @ world.LUMA) * omega  # each direction's share of its region's light
    for count in args.counts:
        rects = world.regions(power, count, solid_angle)
        region_of = np.full(h * w, -1)
        for k, rect in enumerate(rects):
            region_of[np.arange(h * w).reshape(h, w)[rect].ravel()] = k
        suns_r = world.world_suns(radiance, count, by_width=True)
        lit = [k for k, rect in enumerate(rects)
               if np.any(world.LUMA @ np.einsum("ijc,ijk->ck", radiance[rect], world.texel_vectors(h, w)[rect]))]
        assert len(lit) == len(suns_r), "world_suns keeps the regions that carry light, in order"
        fraction_e, hard_e = np.zeros((len(points), 3)), np.zeros((len(points), 3))
        for sun, k in zip(suns_r, lit, strict=True):
            toward = -sun.direction
            light = np.maximum(normals @ toward, 0)[:, None] * (sun.color * sun.sun_strength)
            mine = region_of[texel] == k
            if mine.any():
                share = sees_sky(points, towards[mine], tunnel) @ weight[mine] / weight[mine].sum()
                fraction_e += light * share[:, None]
            hard_e += light * sees_sky(points, toward[None], tunnel)[:, 0:1]
        report(f"{count} regions, exact fraction", fraction_e)
        report(f"{count} regions, hard", hard_e)
        for taps in args.taps:
            tap_e = np.zeros((len(points), 3))
            for sun, k in zip(suns_r, lit, strict=True):
                light = np.maximum(normals @ -sun.direction, 0)[:, None] * (sun.color * sun.sun_strength)
                parts = world.region_taps(radiance, power, world.texel_vectors(h, w), rects[k], taps)
                share = sees_sky(points, parts[:, :3], tunnel) @ parts[:, 3]
                tap_e += light * share[:, None]
            report(f"{count} regions, {taps} taps each", tap_e)
            if args.jitter:
                parts = [p for k in lit for p in world.region_parts(power, rects[k], taps) if power[p].sum() > 0]
                seeds = [jittered_sky(points, normals, radiance, parts, tunnel, seed) for seed in (0, 1)]
                report(f"{count} regions, {taps} parts each, jittered per pixel (seed 0)", seeds[0])
                a, b = image(seeds[0]), image(seeds[1])
                print(f"  noise between seeds 0 and 1: per pixel {metrics.rel_rmse(b, a):.4f}, "
                      f"rel_rmse_8 {metrics.rel_rmse_8(b, a):.4f}")


if __name__ == "__main__":
    main()
