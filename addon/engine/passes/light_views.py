"""Where each light's RSM looks from: one perspective face for a spot, six cube faces for a point or
area light, one orthographic view fitted to the scene bounds for a sun. Pure numpy.

Only what the scene needs: a light outside the scene's bounds spends its texels on the bounds. When
a square view fitted to the bounds has texels at most half as wide as the light's own views (a cube
face, or a spot's face), the light gets that one view instead (a lamp 30 m from a 2 m room: the room's
4 degrees filled at full resolution rather than a few texels of one face). Otherwise a cube face whose
90-degree pyramid misses the bounds is skipped. The bounds are widened by FIT_MARGIN_TEXELS texels at
the far distance first: the direct pass lifts a receiver off its surface by a few texels before it
looks the receiver up, and the lifted point must still lie in a view.

Texels only where they are needed: `resolution` (RsmConfig.resolution) is the most texels a side of a
perspective view has. Its texels are as wide as those of a view of that side spanning the bounds'
diagonal (texel_width_m); a view whose footprint (its width at the farthest depth of the bounds in it)
is narrower gets that many fewer texels, halved while they still cover it (view_texels): a lamp under
the ceiling draws its upward face at 64 texels rather than 256, at the same texel width as its other
faces. A sun keeps `resolution`: its view is fitted to the bounds (and the sky's tiles, sky_light.py,
rely on their size).

An area light's RSM looks from its centre as a Lambertian point, I(w) = P / pi * cos: its VPLs. A
light with a shape (area_light.split_area_light's patches, emissive triangles: Light.emitter) is lit
exactly in the direct pass from its polygons and shadowed from its position.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..area_light import MAX_POLYGONS_PER_LIGHT, Emitter, emitter_radius_m
from ..scene import Light
from ..transforms import box_corners, look_along, orthographic, perspective

KIND_CODE = {"POINT": 0, "SPOT": 0, "SUN": 1, "AREA": 2}
CUBE_AXES = np.array([[1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1]], np.float64)
SINGLE_FACE_MAX_SPOT_RAD = np.radians(120.0)  # wider spots use cube faces (a 90-degree face each)
# How far the bounds are widened before a view is fitted to them or a face is skipped, in the view's
# texels at the far distance: the direct pass's receiver lift (1.5 texels, or EXACT_LIFT_TEXELS plus
# the shadow bias, at most 8) with room to spare.
FIT_MARGIN_TEXELS = 12.0
# A view is fitted to the bounds only where its texels come out at most 1 / FIT_MIN_GAIN as wide as
# those of the view the light has otherwise (its spot's face, or a cube face): a lamp just outside a
# wall keeps its cube faces, which waste few texels on it, and only the faces that see nothing go.
FIT_MIN_GAIN = 2.0
# The fewest texels a side a perspective view is given from its footprint (view_texels): the rsm
# gather's strata (at most 64 a side at RsmConfig.vpl_samples' 4096) each keep a texel or more.
MIN_VIEW_TEXELS = 64


@dataclass(frozen=True)
class LightView:
    """One RSM face of one light, with what the RSM and direct-light shaders need as uniforms."""

    light_index: int
    view_projection: np.ndarray
    position_m: np.ndarray
    face_axis: np.ndarray
    face_index: int  # 0..5 for cube faces (major-axis partition), -1 otherwise
    texel_scale: float  # perspective: texel solid angle at the face axis (sr); sun: texel area (m^2)
    uniforms: dict
    resolution: int  # its RSM's side in texels (view_texels)


def emissive_lights(positions_m: np.ndarray, emission: np.ndarray, scene_extent_m: float, bins: int = 8
                    ) -> list[Light]:
    """Emissive triangles as lamps: triangles are grouped by the cell of a coarse grid (`bins` cells
    along the scene's longest extent) their centroid falls in, one lamp per group: at most bins^3
    lamps, and a small emitter (Sponza's sphere) is one lamp, not hundreds; a triangle larger than a cell
    is split first. Each lamp keeps its triangles (Light.emitter) when it has few enough: the direct pass
    integrates them exactly and shadows them from the lamp's position.

    Cycles' mesh emission is two-sided: each side of a surface of radiance L emits pi L A. Flat groups
    (area-weighted normals mostly agree) become two AREA lights, one per side; closed ones (a sphere:
    normals cancel, the inner side's light stays inside) one isotropic POINT light of pi L A: their RSMs'
    VPLs. Without its triangles a lamp is exact only far from the emitter.
    """
    lum = emission.max(axis=1) if len(emission) else np.zeros(0)
    sel = lum > 0
    if not np.any(sel):
        return []
    cell = max(scene_extent_m / bins, 1e-9)
    # Triangles larger than a cell are split first, so a large panel becomes several lamps: each is
    # shadowed from its own centre, and the shadows soften in as many steps.
    p, e = _subdivided(np.asarray(positions_m, np.float64)[sel], np.asarray(emission, np.float64)[sel], cell)
    cross = np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])
    area = 0.5 * np.linalg.norm(cross, axis=1)
    centroid = p.mean(axis=1)
    lo = centroid.min(axis=0)
    keys = np.floor((centroid - lo) / cell).astype(np.int64)
    _, group = np.unique(keys, axis=0, return_inverse=True)
    lights = []
    for g in range(group.max() + 1):
        m = group.ravel() == g
        flux = np.pi * (e[m] * area[m, None]).sum(axis=0)  # W per colour channel
        total_area = area[m].sum()
        if total_area <= 0 or flux.max() <= 0:
            continue
        weights = flux.max() * area[m] / total_area
        position = (centroid[m] * weights[:, None]).sum(axis=0) / weights.sum()
        net = 0.5 * cross[m].sum(axis=0)  # area-weighted normal sum
        power = float(flux.max())
        color = flux / power
        tris, facing = p[m], np.sign(cross[m] @ net)  # +1 where a triangle winds towards net's side
        if np.linalg.norm(net) > 0.5 * total_area:
            # The emitter is opaque: what its light's surfels reflect back at it stops there (a ceiling
            # 2 cm behind a panel sends most of its light into the panel's back), modelled as a disc of
            # the group's area (disc_view_factor).
            radius = float(np.sqrt(total_area / np.pi))
            lights.append(Light("AREA", position, net, color, power_w=power, name="emissive",
                                occluder_radius_m=radius, emitter=_triangles(tris, e[m], facing)))
            lights.append(Light("AREA", position, -net, color, power_w=power, name="emissive (back)",
                                occluder_radius_m=radius, emitter=_triangles(tris, e[m], -facing)))
        else:
            # Closed (a sphere): each triangle's outer side, as wound, is what can be seen from outside.
            lights.append(Light("POINT", position, [0, 0, -1], color, power_w=power, name="emissive",
                                emitter=_triangles(tris, e[m], np.ones(len(tris)))))
    return lights


def _subdivided(triangles: np.ndarray, radiance: np.ndarray, max_edge_m: float, levels: int = 4):
    """Triangles (k, 3, 3) with radiance (k, 3), each whose longest edge exceeds max_edge_m split into
    four at its edges' midpoints (winding kept), up to `levels` times."""
    for _ in range(levels):
        edges = np.linalg.norm(triangles - np.roll(triangles, -1, axis=1), axis=2).max(axis=1)
        big = edges > max_edge_m
        if not big.any():
            break
        a, b, c = (triangles[big, i] for i in range(3))
        ab, bc, ca = (a + b) / 2, (b + c) / 2, (c + a) / 2
        children = np.concatenate([np.stack(t, axis=1) for t in ((a, ab, ca), (ab, b, bc), (ca, bc, c), (ab, bc, ca))])
        triangles = np.concatenate([triangles[~big], children])
        radiance = np.concatenate([radiance[~big], np.tile(radiance[big], (4, 1))])
    return triangles, radiance


def _triangles(triangles: np.ndarray, radiance: np.ndarray, sided: np.ndarray) -> Emitter | None:
    """Emissive triangles (k, 3, 3) as an Emitter, emitting on the `sided` side of their winding; None
    (the lamp stays a point) when there are too many for the direct pass's per-pixel loop."""
    if len(triangles) > MAX_POLYGONS_PER_LIGHT:
        return None
    vertices = np.concatenate([triangles, triangles[:, 2:3]], axis=1)  # the 4th corner repeats the 3rd
    return Emitter(vertices, np.full(len(triangles), 3), radiance, sided)


def disc_view_factor(height_m, offset_m, radius_m):
    """View factor from a small surface element to a disc parallel to it, `height_m` in front of it and
    `offset_m` off its axis (rsm.frag.glsl's twin): F = (1 - (h^2 + a^2 - r^2) / sqrt((h^2 + a^2 +
    r^2)^2 - 4 a^2 r^2)) / 2 (r^2 / (h^2 + r^2) on the axis; 1 against the disc, 0 beside it)."""
    h2, a2, r2 = (np.square(np.asarray(v, np.float64)) for v in (height_m, offset_m, radius_m))
    root = np.sqrt(np.maximum((h2 + a2 + r2) ** 2 - 4.0 * a2 * r2, 1e-300))
    return 0.5 * (1.0 - (h2 + a2 - r2) / root)


def light_intensity(light: Light) -> np.ndarray:
    """Per-channel radiant intensity (W/sr) at the peak, or the sun's irradiance (W/m^2)."""
    if light.kind == "SUN":
        return light.color * light.sun_strength
    if light.kind == "AREA":
        return light.color * light.power_w / np.pi
    return light.color * light.power_w / (4.0 * np.pi)


def reaches(light: Light, bounds: tuple[np.ndarray, np.ndarray]) -> bool:
    """Whether the light can send any light into the geometry's bounds: not when it emits nothing, a
    spot's cone misses the bounds' enclosing sphere, or a one-sided area light faces away from every
    corner. Conservative (a light that reaches the sphere but not the box is kept); a light that cannot
    reach adds exactly nothing, so skipping its light views changes no image."""
    if not np.any(np.asarray(light.color) > 0) or (light.kind == "SUN" and light.sun_strength <= 0) or (
            light.kind != "SUN" and light.power_w <= 0):
        return False
    lo, hi = (np.asarray(b, np.float64) for b in bounds)
    if light.kind == "SPOT" and light.spot_size_rad < np.pi:
        centre, radius = (lo + hi) / 2.0, float(np.linalg.norm(hi - lo)) / 2.0
        to_centre = centre - light.position_m
        dist = float(np.linalg.norm(to_centre))
        if dist <= radius:
            return True  # the light is inside the sphere
        off_axis = np.arccos(np.clip(np.dot(to_centre / dist, light.direction), -1.0, 1.0))
        return off_axis - np.arcsin(radius / dist) < light.spot_size_rad / 2.0
    if light.kind == "AREA":
        return bool(np.any((box_corners(lo, hi) - light.position_m) @ light.direction > 0.0))
    return True


def texel_width_m(bounds: tuple[np.ndarray, np.ndarray], resolution: int) -> float:
    """The width (m) of a perspective view's texels, whatever its footprint: that of `resolution` texels
    across the bounds' diagonal, the widest footprint a view of the scene has."""
    lo, hi = bounds
    return max(float(np.linalg.norm(np.asarray(hi) - np.asarray(lo))), 1e-9) / resolution


def view_texels(footprint_m: float, texel_m: float, most: int) -> int:
    """Texels a side for a view `footprint_m` wide at its farthest geometry: `most`, halved while half
    as many still cover the footprint at texel_m each, stays even (RSM reductions halve it again) and
    keeps MIN_VIEW_TEXELS."""
    texels = most
    while texels % 2 == 0 and texels // 2 >= MIN_VIEW_TEXELS and (texels // 2) * texel_m >= footprint_m:
        texels //= 2
    return texels


def views_for(light: Light, index: int, bounds: tuple[np.ndarray, np.ndarray], resolution: int) -> list[LightView]:
    """`light`'s RSM views (module docstring): a sun's at `resolution`, a perspective view's at
    view_texels of its footprint, `resolution` at most."""
    lo, hi = bounds
    corners = box_corners(lo, hi)
    if light.kind == "SUN":
        return [_sun_view(light, index, corners, resolution)]
    texel_m = texel_width_m(bounds, resolution)
    far = float(np.max(np.linalg.norm(corners - light.position_m, axis=1))) * 1.01 + 1e-3
    # Depth precision goes with far / near: keep near as large as the scene allows. Outside the
    # bounds, half the distance to them clips nothing; inside, far / 1000 (32-bit depth, ~1e-4 relative).
    outside_m = float(np.linalg.norm(np.maximum(np.maximum(lo - light.position_m, light.position_m - hi), 0.0)))
    near = max(far * 1e-3, 0.5 * outside_m)

    def widened(tan_half: float, texels: int = resolution) -> np.ndarray:
        """The bounds' corners from the light, FIT_MARGIN_TEXELS of a view's `texels` wider."""
        margin_m = FIT_MARGIN_TEXELS * (2.0 * tan_half / texels) * far + 1e-6 * float(np.linalg.norm(hi - lo))
        return box_corners(lo - margin_m, hi + margin_m) - light.position_m

    def texels_for(axis: np.ndarray, fov: float) -> int:
        """view_texels of the view's footprint at the bounds' farthest depth along its axis."""
        depth_m = float(np.clip(np.max((corners - light.position_m) @ axis), near, far))
        return view_texels(2.0 * np.tan(fov / 2.0) * depth_m, texel_m, resolution)

    spot_face = light.kind == "SPOT" and light.spot_size_rad <= SINGLE_FACE_MAX_SPOT_RAD
    # the field of view the light has otherwise: its spot's face, or a cube face's
    own_fov = min(light.spot_size_rad * 1.02, SINGLE_FACE_MAX_SPOT_RAD) if spot_face else np.pi / 2.0
    cone = bounds_cone(corners - light.position_m)  # None: the light is among the bounds
    if cone is not None:
        cone = bounds_cone(widened(np.tan(cone[1])))  # in the fitted view's own texels
    if cone is not None and np.tan(cone[1]) * FIT_MIN_GAIN <= np.tan(own_fov / 2.0):
        texels = texels_for(cone[0], 2.0 * cone[1])
        if texels < resolution:  # its margin in its own, wider texels: the wider view may need more
            cone = bounds_cone(widened(np.tan(cone[1]), texels))
            texels = texels_for(cone[0], 2.0 * cone[1])
        return [_perspective_view(light, index, cone[0], -1, 2.0 * cone[1], near, far, texels)]
    if spot_face:
        return [_perspective_view(light, index, light.direction, -1, own_fov, near, far,
                                  texels_for(light.direction, own_fov))]
    # The faces' margin at `resolution` texels holds their fewer texels' lifts too: a face's texels are
    # at most texel_m wide at its geometry (view_texels), so a lift of up to 8 of them moves a receiver at
    # most 8 diagonal / resolution, less than the margin's 12 x 2 far / resolution (far >= diagonal / 2).
    wide = widened(1.0)
    views = []
    for face, axis in enumerate(CUBE_AXES):
        if light.kind == "AREA" and np.dot(axis, light.direction) < -0.5:
            continue  # the face behind a one-sided emitter receives nothing
        if not face_meets(axis, wide):
            continue  # nothing of the scene lies in this face's pyramid
        views.append(_perspective_view(light, index, axis, face, np.pi / 2.0, near, far, texels_for(axis, np.pi / 2.0),
                                       resolution))
    return views


def bounds_cone(corners: np.ndarray) -> tuple[np.ndarray, float] | None:
    """(axis, half field of view in rad) of the square perspective view from the origin, along the
    direction to the box's centre, that holds the box of these corners (relative to the light), as
    _perspective_view orients it (look_along); None when the origin lies in the box or some corner lies
    at or behind the origin's plane across that direction."""
    lo, hi = corners.min(axis=0), corners.max(axis=0)
    if np.all(lo <= 0.0) and np.all(hi >= 0.0):
        return None
    centre = (lo + hi) / 2.0
    axis = centre / np.linalg.norm(centre)
    local = corners @ look_along(np.zeros(3), axis)[:3, :3].T  # view space: -z along the axis
    depth = -local[:, 2]
    if np.min(depth) <= 0.0:
        return None
    return axis, float(np.arctan(np.max(np.abs(local[:, :2]) / depth[:, None])))


def face_meets(axis: np.ndarray, corners: np.ndarray) -> bool:
    """Whether the cube face along `axis` (its 90-degree pyramid from the origin: the points whose
    coordinate along the axis is positive and at least each other coordinate's magnitude) can meet the
    box of these corners (relative to the light). False only when every corner lies outside one of the
    pyramid's five planes (so the box does); it may say True of a box that misses."""
    along = corners @ axis
    if np.all(along < 0.0):
        return False
    for other in np.flatnonzero(axis == 0.0):
        for sign in (1.0, -1.0):
            if np.all(sign * corners[:, other] > along):
                return False
    return True


def _common_uniforms(light: Light, emit_axis: np.ndarray, texel_scale: float) -> dict:
    spot = light.kind == "SPOT"
    return {
        "light_pos_ws": light.position_m,
        "texel_scale": texel_scale,
        "emit_axis": emit_axis,
        "light_kind": KIND_CODE[light.kind],
        "light_color_intensity": light_intensity(light),
        "spot_cos_half": float(np.cos(light.spot_size_rad / 2.0)) if spot else -1.0,
        "spot_blend": float(light.spot_blend) if spot else 0.0,
        "occluder_radius": float(light.occluder_radius_m),
        # A sun's angular radius (its tangent): its shadows' penumbra (direct_light's soft shadows).
        "sun_tan_half": float(np.tan(light.sun_angle_rad / 2.0)) if light.kind == "SUN" else 0.0,
        # A light with a shape: the disc it looks like, its shadows' penumbra (direct_light's soft shadows).
        "emitter_radius_m": emitter_radius_m(light.emitter, closed=light.kind != "AREA")
        if light.emitter is not None else 0.0,
        # The RSM's surfel areas are scaled by it: 1 but in the sky's RSM tiles (sky_light.table).
        "area_weight": 1.0,
    }


def _perspective_view(light, index, axis, face, fov, near, far, resolution, most=None) -> LightView:
    """A perspective view of `resolution` texels; a cube face (`face` >= 0) also carries the share of its
    texels' lift that a face of `most` texels has (direct_light's face partition: the same for all faces)."""
    view = look_along(light.position_m, axis)
    vp = perspective(fov, near, far) @ view
    texel_scale = (2.0 * np.tan(fov / 2.0) / resolution) ** 2
    uniforms = {"light_view_projection": vp, "light_view_projection_inverse": np.linalg.inv(vp),
                "face_axis": axis, "face_index": face, "face_lift_share": resolution / (most or resolution),
                **_common_uniforms(light, light.direction, texel_scale)}
    return LightView(index, vp, light.position_m, np.asarray(axis, np.float64), face, texel_scale, uniforms,
                     resolution)


def _sun_view(light, index, corners, resolution) -> LightView:
    center = corners.mean(axis=0)
    view = look_along(center, light.direction)
    local = (view @ np.c_[corners, np.ones(8)].T).T[:, :3]
    (x0, y0, z0), (x1, y1, z1) = local.min(axis=0), local.max(axis=0)
    pad = 1e-3 * max(x1 - x0, y1 - y0, z1 - z0, 1e-3)
    proj = orthographic(x0 - pad, x1 + pad, y0 - pad, y1 + pad, -z1 - pad, -z0 + pad)
    vp = proj @ view
    texel_scale = (x1 - x0 + 2 * pad) * (y1 - y0 + 2 * pad) / resolution**2
    uniforms = {"light_view_projection": vp, "face_axis": light.direction, "face_index": -1,
                **_common_uniforms(light, light.direction, texel_scale)}
    return LightView(index, vp, center, light.direction, -1, texel_scale, uniforms, resolution)
