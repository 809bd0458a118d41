"""Area emitters with their shape: polygon irradiance, the patches an area light is split into, and the
emitter table the direct-light pass reads. Pure numpy (the GLSL twin is gpu_shaders/common/polygon.glsl).

Why: a Lambertian point at the centre of a 1 m square light is exact far away and wrong near it (a
point gives hard, misplaced shadows, and under-lights a ceiling 1 cm above a panel). The unshadowed
irradiance of a polygon of uniform radiance L is exact in closed form (Lambert's formula for a
polygon, clipped to the receiver's horizon):

    E(p, n) = L / 2 * | sum_i theta_i * (n . g_i) |,  a_i = unit (v_i - p), theta_i = angle(a_i, a_i+1),
                                                     g_i = unit (a_i x a_i+1)

so each light is split into `patches` (a grid over a rectangle, sectors of an ellipse): each patch has
its exact unshadowed irradiance and soft shadows from its own RSM, as a disc of its area
(emitter_radius_m; docs/DIRECT.md), and the light's total stays exact. Emissive meshes become the
same kind of emitter, their triangles the polygons (light_views.emissive_lights).

Units: radiance W/m^2/sr per colour; polygon_irradiance returns E / L (sr, the cosine-weighted solid
angle), so E = L * polygon_irradiance and Cycles' Diffuse Direct = E / pi.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

MAX_VERTICES = 4            # a row of the emitter table: triangles and quads
MAX_POLYGONS_PER_LIGHT = 64  # a light with more (a dense emissive mesh) keeps the point model: the
#                             direct pass loops over a light's polygons at every pixel
ELLIPSE_SIDES = 16          # a disk or ellipse is a polygon of this many sides with the ellipse's area
TABLE_TEXELS_PER_ROW = MAX_VERTICES + 1  # the vertices, then (radiance rgb, sidedness)


@dataclass(frozen=True)
class Emitter:
    """The polygons of one light: vertices (k, MAX_VERTICES, 3) m (unused corners repeat the last),
    counts (k,) 3 or 4, radiance (k, 3) W/m^2/sr, sided (k,): +1 emits on the side its winding's normal
    ((v1 - v0) x (v2 - v0)) points to, -1 on the other, 0 on both."""

    vertices: np.ndarray
    counts: np.ndarray
    radiance: np.ndarray
    sided: np.ndarray = field(default=None)

    def __post_init__(self):
        if self.sided is None:
            object.__setattr__(self, "sided", np.ones(len(self.counts)))


def polygon_irradiance(p: np.ndarray, n: np.ndarray, vertices: np.ndarray) -> float:
    """E / L at point p with unit normal n from the planar polygon `vertices` (k, 3), the part above
    p's horizon only (clipped), whichever way the polygon winds: the cosine-weighted solid angle (sr)."""
    rel = [np.asarray(v, np.float64) - p for v in vertices]
    clipped = []
    for i, a in enumerate(rel):
        b = rel[(i + 1) % len(rel)]
        da, db = float(np.dot(n, a)), float(np.dot(n, b))
        if da > 0.0:
            clipped.append(a)
        if (da > 0.0) != (db > 0.0):
            clipped.append(a + (b - a) * (da / (da - db)))
    if len(clipped) < 3:
        return 0.0
    total = 0.0
    for i, a in enumerate(clipped):
        b = clipped[(i + 1) % len(clipped)]
        a, b = a / np.linalg.norm(a), b / np.linalg.norm(b)
        cross = np.cross(a, b)
        length = np.linalg.norm(cross)
        if length > 1e-300:
            # atan2 rather than acos: exact for the tiny angles of a small, far polygon
            total += np.arctan2(length, np.dot(a, b)) * np.dot(n, cross) / length
    return 0.5 * abs(total)


def outline(shape: str, size_x_m: float, size_y_m: float) -> np.ndarray:
    """The light's outline in its local XY plane (k, 2), counter-clockwise seen from its front: a
    rectangle's 4 corners, an ellipse's ELLIPSE_SIDES-gon scaled to the ellipse's area (pi a b)."""
    hx, hy = 0.5 * size_x_m, 0.5 * size_y_m
    if shape in ("SQUARE", "RECTANGLE"):
        return np.array([[-hx, -hy], [hx, -hy], [hx, hy], [-hx, hy]])
    k = ELLIPSE_SIDES
    scale = np.sqrt(np.pi / (0.5 * k * np.sin(2.0 * np.pi / k)))  # polygon area = ellipse area
    t = 2.0 * np.pi * np.arange(k) / k
    return scale * np.c_[hx * np.cos(t), hy * np.sin(t)]


def _local_axes(light) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(x, y, front normal) of an area light: Blender's local X, Y, and -Z (where it emits)."""
    front = np.asarray(light.direction, np.float64)
    x = np.asarray(light.axis_x, np.float64)
    x = x - front * np.dot(x, front)
    x /= max(np.linalg.norm(x), 1e-30)
    y = np.cross(-front, x)  # local Y = Z x X with Z = -front
    return x, y, front


def _patch_polygons(light, patches_per_side: int) -> list[np.ndarray]:
    """The patches' polygons (each (k, 2) in local XY): a grid over a rectangle, equal sectors of an
    ellipse (each a fan of the outline's sides around the centre)."""
    n = patches_per_side
    if light.area_shape in ("SQUARE", "RECTANGLE"):
        hx, hy = 0.5 * light.size_x_m, 0.5 * light.size_y_m
        xs, ys = np.linspace(-hx, hx, n + 1), np.linspace(-hy, hy, n + 1)
        return [np.array([[xs[i], ys[j]], [xs[i + 1], ys[j]], [xs[i + 1], ys[j + 1]], [xs[i], ys[j + 1]]])
                for j in range(n) for i in range(n)]
    ring = outline(light.area_shape, light.size_x_m, light.size_y_m)
    sectors = min(n * n, ELLIPSE_SIDES)  # as many patches as a grid would have, each whole sides
    edges = np.array_split(np.arange(ELLIPSE_SIDES), sectors)
    return [np.vstack([[0.0, 0.0], ring[e], ring[(e[-1] + 1) % ELLIPSE_SIDES]]) for e in edges]


def _fan(polygon: np.ndarray) -> list[np.ndarray]:
    """A convex polygon as quads and triangles of at most MAX_VERTICES corners, fanned from vertex 0."""
    out, i = [], 1
    while i + 1 < len(polygon):
        j = min(i + MAX_VERTICES - 2, len(polygon) - 1)
        out.append(np.vstack([polygon[0], polygon[i:j + 1]]))
        i = j
    return out


def _rows(polygons: list[np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
    """(vertices (k, MAX_VERTICES, 3), counts (k,)) with unused corners repeating the last one."""
    verts = np.zeros((len(polygons), MAX_VERTICES, 3))
    counts = np.array([len(p) for p in polygons])
    for r, poly in enumerate(polygons):
        verts[r, : len(poly)] = poly
        verts[r, len(poly):] = poly[-1]
    return verts, counts


def split_area_light(light, patches_per_side: int) -> list:
    """An AREA light of size > 0 as patch lights: each at its patch's centroid, with the patch's share of
    the power and its polygon(s) as its Emitter, so the direct pass integrates the shape exactly and
    soft-shadows each patch from its own RSM. Radiance L = P / (pi A) over the (polygonal) outline's area A."""
    x, y, front = _local_axes(light)
    area_m2 = _polygon_area(outline(light.area_shape, light.size_x_m, light.size_y_m))
    if area_m2 <= 0.0 or light.power_w <= 0.0:
        return [light]  # a zero-size light stays a Lambertian point: its limit
    radiance = np.asarray(light.color, np.float64) * light.power_w / (np.pi * area_m2)
    patches = []
    for local in _patch_polygons(light, patches_per_side):
        patch_area = _polygon_area(local)
        centre2 = _polygon_centroid(local)
        # Local XY is counter-clockwise seen from behind (x cross y is the back): reversed, the
        # winding's normal is the front, the side the table's sidedness +1 emits on.
        world = [light.position_m + x * u + y * v for u, v in local[::-1]]
        verts, counts = _rows(_fan(np.array(world)))
        emitter = Emitter(verts, counts, np.tile(radiance, (len(counts), 1)), np.ones(len(counts)))
        centre = light.position_m + x * centre2[0] + y * centre2[1]
        patches.append(replace(light, position_m=centre, power_w=light.power_w * patch_area / area_m2,
                               emitter=emitter))
    return patches


def _polygon_area(poly2: np.ndarray) -> float:
    x, y = poly2[:, 0], poly2[:, 1]
    return 0.5 * abs(float(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1))))


def _polygon_centroid(poly2: np.ndarray) -> np.ndarray:
    x, y = poly2[:, 0], poly2[:, 1]
    cross = x * np.roll(y, -1) - np.roll(x, -1) * y
    a = 0.5 * cross.sum()
    if abs(a) < 1e-300:
        return poly2.mean(axis=0)
    return np.array([((x + np.roll(x, -1)) * cross).sum(), ((y + np.roll(y, -1)) * cross).sum()]) / (6.0 * a)


def emitter_radius_m(emitter: Emitter, closed: bool) -> float:
    """The radius (m) of the disc an emitter looks like from its front, for its soft shadows' penumbra
    (the direct pass): a disc of the polygons' area for a flat emitter, of a quarter of it for a closed
    one (a sphere's silhouette is a quarter of its surface). A row's area is half its diagonals' cross
    product, exact for a planar quad and, with the 4th corner repeating the 3rd, for a triangle."""
    v = np.asarray(emitter.vertices, np.float64)
    area_m2 = 0.5 * np.linalg.norm(np.cross(v[:, 2] - v[:, 0], v[:, 3] - v[:, 1]), axis=1).sum()
    return float(np.sqrt(area_m2 / (4.0 * np.pi if closed else np.pi)))


def emitter_table(lights: list) -> tuple[np.ndarray, list[tuple[int, int]]]:
    """The direct pass's emitter table (rows, TABLE_TEXELS_PER_ROW, 4) float32 for every light with an
    Emitter, and per light its (first row, row count), (0, 0) for lights without one. A row: texels
    0..3 the vertices (xyz, w = vertex count in texel 0), texel 4 (radiance rgb, sidedness)."""
    rows, ranges = [], []
    for light in lights:
        e = getattr(light, "emitter", None)
        if e is None:
            ranges.append((0, 0))
            continue
        first = sum(len(r) for r in rows)
        block = np.zeros((len(e.counts), TABLE_TEXELS_PER_ROW, 4), np.float32)
        block[:, :MAX_VERTICES, :3] = e.vertices
        block[:, 0, 3] = e.counts
        block[:, MAX_VERTICES, :3] = e.radiance
        block[:, MAX_VERTICES, 3] = e.sided
        rows.append(block)
        ranges.append((first, len(e.counts)))
    table = np.concatenate(rows) if rows else np.zeros((1, TABLE_TEXELS_PER_ROW, 4), np.float32)
    return table, ranges
