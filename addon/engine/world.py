"""The world as a light: an environment map of radiance split into regions, each a sun. Pure numpy.

Why suns: every method already lights with suns (an orthographic RSM each: soft visibility from K of
them, VPLs for the indirect light, the same in every method's light field). A region R of the sky
lights a surface of normal n with E = int_R L(w) max(0, n.w) dw; while R lies wholly above the
surface's horizon the max is inactive and E = n . V_R with V_R = int_R L(w) w dw, the region's vector
irradiance. So a sun along V_R of strength |V_R| is exact for every receiver whose horizon does not cut
R; the partition splits first at the horizon plane of floors and ceilings (the equator), then each
region at its power median along its wider side, so the brightest parts (a sun disc in an HDRI) get
the smallest regions.

Map layout (the capture writes it so, bridge/world_capture.py): equirectangular, float32 (h, w, 3) W/m^2/sr
per colour, row 0 = up (+z), column c = longitude 2 pi (c + 0.5) / w - pi about +z with longitude 0
along +x (direction (cos lat cos lon, cos lat sin lon, sin lat)).
"""

from __future__ import annotations

import heapq

import numpy as np

from .scene import Light

LUMA = np.array([0.2126, 0.7152, 0.0722])  # Rec.709 luminance: power is split by what the eye weighs


def directions(height: int, width: int) -> tuple[np.ndarray, np.ndarray]:
    """Per texel its unit direction (h, w, 3) and solid angle (h, w) in sr (summing to 4 pi)."""
    lat = np.pi / 2 - np.pi * (np.arange(height) + 0.5) / height
    lon = 2 * np.pi * (np.arange(width) + 0.5) / width - np.pi
    lat_g, lon_g = np.meshgrid(lat, lon, indexing="ij")
    d = np.stack([np.cos(lat_g) * np.cos(lon_g), np.cos(lat_g) * np.sin(lon_g), np.sin(lat_g)], axis=-1)
    # Exact band areas: 2 pi (sin(top) - sin(bottom)) / width per texel of a row.
    edges = np.pi / 2 - np.pi * np.arange(height + 1) / height
    band = 2 * np.pi * (np.sin(edges[:-1]) - np.sin(edges[1:])) / width
    return d, np.repeat(band[:, None], width, axis=1)


def downsample(fine: np.ndarray, factor: int) -> np.ndarray:
    """A map of `factor` x `factor` times fewer texels (h / factor, w / factor, c): each texel the mean
    of the fine texels it holds, weighted by their solid angles, so every texel keeps its int L dw."""
    h, w, c = fine.shape
    if h % factor or w % factor:
        raise ValueError(f"a {w} x {h} map does not split into {factor} x {factor} blocks")
    _, omega = directions(h, w)
    blocks = (h // factor, factor, w // factor, factor)
    weighted = (np.asarray(fine, np.float64) * omega[..., None]).reshape(*blocks, c).sum(axis=(1, 3))
    return weighted / omega.reshape(blocks).sum(axis=(1, 3))[..., None]


def texel_vectors(height: int, width: int) -> np.ndarray:
    """Per texel int w dw over its latitude-longitude rectangle (h, w, 3), in closed form: a uniform
    map's vector irradiance sums exactly (a floor under a uniform sky gets pi L, not a quadrature of it)."""
    lat = np.pi / 2 - np.pi * np.arange(height + 1) / height           # row edges, top to bottom
    lon = 2 * np.pi * np.arange(width + 1) / width - np.pi            # column edges
    lat0, lat1 = lat[1:], lat[:-1]                                     # bottom, top of each row
    cos2 = (lat1 - lat0) / 2 + (np.sin(2 * lat1) - np.sin(2 * lat0)) / 4  # int cos^2(lat) dlat
    z = (np.sin(lat1) ** 2 - np.sin(lat0) ** 2) / 2                     # int sin cos dlat
    x = np.sin(lon[1:]) - np.sin(lon[:-1])                             # int cos(lon) dlon
    y = np.cos(lon[:-1]) - np.cos(lon[1:])                             # int sin(lon) dlon
    dlon = lon[1:] - lon[:-1]
    return np.stack([cos2[:, None] * x[None, :], cos2[:, None] * y[None, :], z[:, None] * dlon[None, :]], axis=-1)


def constant_map(radiance: np.ndarray, height: int = 16, width: int = 32) -> np.ndarray:
    return np.broadcast_to(np.asarray(radiance, np.float32), (height, width, 3)).copy()


def regions(power: np.ndarray, count: int, solid_angle: np.ndarray | None = None) -> list[tuple[slice, slice]]:
    """Split the map (per-texel power (h, w)) into `count` rectangles of texels: the two hemispheres
    first, then repeatedly the region of largest power at its power median along its longer side
    (in texels weighted by cos(lat) for longitude). Regions with no power are never split. The
    rectangles come in the order of the splits' tree (each split's halves where the region was).

    With `solid_angle` (per texel, sr) the region split next is the one of largest power x sqrt(solid
    angle): a shadow cast by one direction in place of a region errs by the region's light times its
    angular width, so a dim but wide region (the ground seen through a window) is split too, not only
    the bright sky.

    A heap of the unsplit regions by that priority: each split costs the two halves' sums, so 1024
    regions of a 64 x 128 map take milliseconds (rescoring every region at every split took 4 s)."""
    h, w = power.shape
    roots = [(slice(0, h // 2), slice(0, w)), (slice(h // 2, h), slice(0, w))] if h >= 2 else [(slice(0, h),
                                                                                              slice(0, w))]

    def priority(rect) -> float:
        return float(power[rect].sum()) * (1.0 if solid_angle is None else float(np.sqrt(solid_angle[rect].sum())))

    rects = list(roots)  # every region made, by id
    halves: dict[int, tuple[int, int]] = {}  # id of a split region -> its halves' ids
    heap = [(-priority(r), i) for i, r in enumerate(roots)]
    heapq.heapify(heap)
    leaves = len(roots)
    while leaves < count and heap:
        _, i = heapq.heappop(heap)
        split = _split(power, rects[i])
        if split is None:
            continue  # never splittable: dropped from the heap
        halves[i] = (len(rects), len(rects) + 1)
        for half in split:
            heapq.heappush(heap, (-priority(half), len(rects)))
            rects.append(half)
        leaves += 1
    out, stack = [], list(range(len(roots)))[::-1]
    while stack:  # the leaves, depth first
        i = stack.pop()
        if i in halves:
            stack.extend(halves[i][::-1])
        else:
            out.append(rects[i])
    return out


def _split(power: np.ndarray, rect: tuple[slice, slice]):
    rows, cols = rect
    n_rows, n_cols = rows.stop - rows.start, cols.stop - cols.start
    block = power[rect]
    if block.sum() <= 0 or n_rows * n_cols < 2:
        return None
    mid_lat = np.pi / 2 - np.pi * (rows.start + rows.stop) / 2 / power.shape[0]
    along_rows = n_rows > n_cols * max(np.cos(mid_lat), 0.05) and n_rows > 1 or n_cols < 2
    profile = block.sum(axis=1) if along_rows else block.sum(axis=0)
    cut = int(np.searchsorted(np.cumsum(profile), 0.5 * profile.sum()))
    cut = min(max(cut, 1), len(profile) - 1)  # both halves keep at least one texel
    if along_rows:
        return (slice(rows.start, rows.start + cut), cols), (slice(rows.start + cut, rows.stop), cols)
    return (rows, slice(cols.start, cols.start + cut)), (rows, slice(cols.start + cut, cols.stop))


def world_suns(world_map: np.ndarray, count: int, by_width: bool = False) -> list[Light]:
    """The map's light as at most `count` suns (module docstring): each region's vector irradiance V_c
    per colour; the sun shines along -(luminance-weighted direction), strength |V| along it. by_width:
    regions split by power x angular width (`regions`), as the sky's shadowed directions want."""
    return sky_regions(world_map, count, 0, by_width)[0]


def sky_regions(world_map: np.ndarray, count: int, taps: int,
                by_width: bool = True) -> tuple[list[Light], np.ndarray]:
    """world_suns, and per sun `taps` rays over its region with their shares of its light (suns,
    (len(suns), taps, 4): xyz the unit direction towards the sky, w the share; region_taps).

    Why: a region's shadow is the share of its light a point sees, and a region is not a disc: a strip
    of sky just above a window's horizon lights a patch of wall as narrow as the strip. Visibility
    tested exactly along 8 such rays per region, window-sky's direct light is within 0.028 of Cycles
    at 186 regions (0.121 from each region's one direction; tools/window_sky_oracle.py)."""
    radiance = np.asarray(world_map, np.float64)
    _, solid_angle = directions(*radiance.shape[:2])
    vectors = texel_vectors(*radiance.shape[:2])
    power = (radiance @ LUMA) * solid_angle
    suns, tap_rows = [], []
    for rect in regions(power, count, solid_angle if by_width else None):
        vec = np.einsum("ijc,ijk->ck", radiance[rect], vectors[rect])  # (3 colours, xyz): V per colour
        luma_vec = LUMA @ vec
        norm = np.linalg.norm(luma_vec)
        if norm <= 0:
            continue
        toward = luma_vec / norm  # where the region lies, seen from the scene
        strength = np.maximum(vec @ toward, 0.0)  # per colour, W/m^2 on a surface facing it
        peak = float(strength.max())
        if peak <= 0:
            continue
        # As wide as the region: a cone of the region's solid angle (omega = 2 pi (1 - cos half-angle)).
        omega = float(solid_angle[rect].sum())
        angle = 2.0 * float(np.arccos(np.clip(1.0 - omega / (2.0 * np.pi), -1.0, 1.0)))
        suns.append(Light("SUN", toward * 1e3, -toward, strength / peak, sun_strength=peak, sun_angle_rad=angle,
                          name="world"))
        if taps:
            tap_rows.append(region_taps(radiance, power, vectors, rect, taps))
    return suns, np.array(tap_rows, np.float64).reshape(len(suns), taps, 4) if taps else np.zeros((len(suns), 0, 4))


def region_parts(power: np.ndarray, rect: tuple[slice, slice], taps: int) -> list[tuple[slice, slice]]:
    """Region `rect` of the map split into at most `taps` rectangles: the part of largest power split
    first, at its power median (`_split`), until there are `taps` or none splits further."""
    parts = [rect]
    while len(parts) < taps:
        order = sorted(range(len(parts)), key=lambda i: -float(power[parts[i]].sum()))
        split = next(((i, halves) for i in order if (halves := _split(power, parts[i])) is not None), None)
        if split is None:
            break  # every part is one texel, or dark
        i, halves = split
        parts[i:i + 1] = list(halves)
    return parts


def region_taps(radiance: np.ndarray, power: np.ndarray, vectors: np.ndarray, rect: tuple[slice, slice],
                taps: int) -> np.ndarray:
    """(taps, 4): per part of `region_parts` its direction towards the sky (its luminance-weighted
    vector irradiance, `vectors` = texel_vectors) and its share of the power of the parts that carry
    light. Parts that carry none, and taps beyond the parts, are 0."""
    out = np.zeros((taps, 4))
    for j, part in enumerate(region_parts(power, rect, taps)):
        vec = LUMA @ np.einsum("ijc,ijk->ck", radiance[part], vectors[part])
        norm = float(np.linalg.norm(vec))
        if norm > 0:
            out[j] = (*(vec / norm), float(power[part].sum()))
    total = out[:, 3].sum()
    out[:, 3] = out[:, 3] / total if total > 0 else 0.0
    return out


AXES = np.array([[1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1]], np.float64)


def sun_strengths(suns: list[Light]) -> np.ndarray:
    """Each sun's strength in luminance (W/m^2 normal to it, colours weighed by LUMA)."""
    return np.array([s.sun_strength * float(s.color @ LUMA) for s in suns])


def power_shares(suns: list[Light]) -> np.ndarray:
    """Each sun's share of the suns' summed strength (sun_strengths); equal shares when all are dark."""
    strengths = sun_strengths(suns)
    total = strengths.sum()
    return strengths / total if total > 0 else np.full(len(suns), 1.0 / max(len(suns), 1))


def world_share(world_lights: list[Light], lamps: list[Light], scene_radius_m: float) -> float:
    """The world's share of the scene's direct light, E_world / (E_world + sum E_lamp), in luminance:
    E_world the irradiance of the best-lit axis-facing surface under the world's suns (pi L for a floor
    under a uniform sky), E_lamp a sun's strength, or a lamp's power / (4 pi r^2) at the scene's radius
    r. 0 without world light."""
    if not world_lights:
        return 0.0
    toward = np.array([-s.direction for s in world_lights])
    world_e = float(np.max(np.maximum(AXES @ toward.T, 0.0) @ sun_strengths(world_lights)))
    lamps_e = 0.0
    for lamp in lamps:
        if lamp.kind == "SUN":
            lamps_e += lamp.sun_strength * float(lamp.color @ LUMA)
        else:
            lamps_e += lamp.power_w * float(lamp.color @ LUMA) / (4.0 * np.pi * max(scene_radius_m, 1e-9) ** 2)
    return world_e / (world_e + lamps_e) if world_e > 0 else 0.0


def sky_direction_count(world_lights: list[Light], lamps: list[Light], most: int, least: int,
                        scene_radius_m: float) -> int:
    """How many directions the sky's direct light gets: `most` times the world's share of the scene's
    direct light (`world_share`), at least `least`; 0 without world light. A world that gives a small
    part of the light (Sponza's grey world beside its sun: 2.5 %) needs few directions for the same
    error in the image; a sky lighting a room through its window, most of them."""
    if not world_lights:
        return 0
    share = world_share(world_lights, lamps, scene_radius_m)
    return int(min(most, max(least, round(most * share))))
