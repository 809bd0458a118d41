"""The probe volume for engines (`bake --target probes`; docs/BAKE.md, docs/PROBES.md): what method
`probes` solved, as arrays in a documented layout. numpy only; the bridge writes the files.

An engine gets six textures and a layout:
- `sh`: the L2 SH of the radiance arriving at each probe (W/m^2/sr, by direction of arrival), the
  paper's nine coefficients per colour (sh.py's basis and order). With the SH encoding these are the
  solve's own; with the irradiance encoding they are the irradiance cube maps projected to SH and
  divided by the cosine lobe's band factors (E = A_l L per band, so L = E / A_l: exact for a field of
  bands 0..2, a least-squares fit otherwise).
- `irradiance`: each probe's irradiance cube map E(n) (W/m^2) at IRRADIANCE_TEXELS^2 normals a face, in
  the capture's tile layout. With the SH encoding, E(n) = max(0, sum_i h_l A_l c_i Y_i(n)), what the
  renderer's lookup evaluates (h_l: sh.IRRADIANCE_WINDOW_L2, the deringing window); with the
  irradiance encoding, the solve's own maps.
- `moments`: the mean and mean square of the distance (m, m^2) from each probe to what its capture
  texels see (the lookup's Chebyshev visibility), at the capture's face_texels^2 a face.
- `offsets`: each probe's move off its grid position (m; ProbesConfig.relocate, else 0), one texel per
  probe in the state's layout: the probe sits at its grid position + offset, and the moments are
  distances from there.
- `irradiance_oct`, `moments_oct`: the same irradiance and moments in DDGI's layout (Majercik et al.
  2019), for engines built on it: per probe a square octahedral tile of OCT_IRRADIANCE_TEXELS^2
  (OCT_MOMENT_TEXELS^2) texels inside a one-texel border, tile (ix, iy + ny iz). Each interior texel is
  Bounce's own lookup of that probe at the texel's direction (the cube maps read bilinearly within
  a face, as the renderer reads them, or E evaluated from the SH); the border repeats the interior
  texel that the octahedron folds it onto, so bilinear filtering across a tile's edge stays on the
  sphere (`octahedral_border`).
Atlases are (h, w, 3) float32 with row 0 the texture's first (bottom) row, as the GPU holds them.
"""

from __future__ import annotations

import numpy as np

from . import sh
from .probe_grid import FACE_FRAMES, SH_COEFFS, ProbeGrid, texel_directions, texel_solid_angles

FORMAT = "bounce-probes"
FILES = ("sh", "irradiance", "moments", "offsets", "irradiance_oct", "moments_oct")
VERSION = 3  # 2: the offsets (relocated probes); 3: the octahedral atlases

# Interior texels per side of a probe's octahedral tiles, inside their one-texel border: tiles of 8 x 8
# (irradiance) and 16 x 16 (moments), DDGI's published sizes and RTXGI's defaults.
OCT_IRRADIANCE_TEXELS = 6
OCT_MOMENT_TEXELS = 14


def sh_grid(grid: ProbeGrid, sh_table: np.ndarray) -> np.ndarray:
    """(nz, ny, nx, 9, 3) coefficients from the SH table ((ny nz, 9 nx, >= 3): coefficient c of probe
    (ix, iy, iz) at row iy + ny iz, column c nx + ix)."""
    nx, ny, nz = grid.dims
    table = np.asarray(sh_table, np.float64)[..., :3]
    return table.reshape(nz, ny, SH_COEFFS, nx, 3).transpose(0, 1, 3, 2, 4)


def sh_table(grid: ProbeGrid, coeffs: np.ndarray) -> np.ndarray:
    """The inverse of sh_grid: (ny nz, 9 nx, 3) from (nz, ny, nx, 9, 3)."""
    nx, ny, nz = grid.dims
    return np.asarray(coeffs).transpose(0, 1, 3, 2, 4).reshape(ny * nz, SH_COEFFS * nx, 3)


def _face_origin(grid: ProbeGrid, n: int, p, face) -> tuple:
    """Atlas column and row of texel (0, 0) of probe p's face in an n x n tiled atlas (probe.glsl's
    tile_origin); p and face broadcast."""
    cols = grid.tiles_per_row
    return 3 * n * (p % cols) + n * (face % 3), 2 * n * (p // cols) + n * (face // 3)


def _face_texels(grid: ProbeGrid, n: int) -> tuple[np.ndarray, np.ndarray]:
    """Atlas rows and columns (P, 6, n, n) of every probe's face texels in an n x n tiled atlas."""
    x0, y0 = _face_origin(grid, n, np.arange(grid.count)[:, None, None, None], np.arange(6)[None, :, None, None])
    j = np.arange(n)[None, None, :, None]
    i = np.arange(n)[None, None, None, :]
    return np.broadcast_to(y0 + j, (grid.count, 6, n, n)), np.broadcast_to(x0 + i, (grid.count, 6, n, n))


def _sh_irradiance(grid: ProbeGrid, coeffs: np.ndarray, normals: np.ndarray) -> np.ndarray:
    """(P, d, 3) irradiance of SH radiance (nz, ny, nx, 9, 3) at unit normals (d, 3), clamped at 0, as
    the lookup evaluates it: E = max(0, sum_i h_l A_l c_i Y_i(n)), h_l the deringing window."""
    per_probe = np.asarray(coeffs, np.float64).reshape(grid.count, SH_COEFFS, 3)  # probe order p
    return np.maximum(np.einsum("pck,dc->pdk", per_probe, sh.windowed_cosine_lobe_l2(normals)), 0.0)


def irradiance_from_sh(grid: ProbeGrid, coeffs: np.ndarray, n: int) -> np.ndarray:
    """The irradiance atlas (grid.tiled_size(n) as (h, w, 3), W/m^2) of SH radiance (nz, ny, nx, 9, 3):
    E at every face texel's centre normal, clamped at 0, as the lookup evaluates it."""
    e = _sh_irradiance(grid, coeffs, texel_directions(n).reshape(-1, 3)).reshape(grid.count, 6, n, n, 3)
    w, h = grid.tiled_size(n)
    atlas = np.zeros((h, w, 3))
    rows, cols = _face_texels(grid, n)
    atlas[rows, cols] = e
    return atlas


def sh_from_irradiance(grid: ProbeGrid, atlas: np.ndarray, n: int) -> np.ndarray:
    """SH radiance (nz, ny, nx, 9, 3) whose cosine convolution is the irradiance atlas: E projected over
    the texels' exact solid angles, each band divided by its factor A_l."""
    rows, cols = _face_texels(grid, n)
    e = np.asarray(atlas, np.float64)[..., :3][rows, cols]                       # (P, 6, n, n, 3)
    basis = sh.basis_l2(texel_directions(n))                                      # (6, n, n, 9)
    d_omega = np.broadcast_to(texel_solid_angles(n), (6, n, n))
    e_coeffs = np.einsum("pfjik,fjic,fji->pck", e, basis, d_omega)
    factors = np.array([sh.BAND_FACTORS[sh.band_of(i)] for i in range(SH_COEFFS)])
    nx, ny, nz = grid.dims
    return (e_coeffs / factors[None, :, None]).reshape(nz, ny, nx, SH_COEFFS, 3)


def octahedral_decode(uv: np.ndarray) -> np.ndarray:
    """Unit directions (..., 3) of octahedral coordinates uv (..., 2) in [-1, 1]^2: the tile's centre
    looks along +z, its edges' midpoints along the horizon, its corners along -z (the lower half of the
    octahedron folded out over the square's corners)."""
    uv = np.asarray(uv, np.float64)
    u, v = uv[..., 0], uv[..., 1]
    z = 1.0 - np.abs(u) - np.abs(v)
    lower = z < 0.0
    x = np.where(lower, (1.0 - np.abs(v)) * np.where(u >= 0.0, 1.0, -1.0), u)
    y = np.where(lower, (1.0 - np.abs(u)) * np.where(v >= 0.0, 1.0, -1.0), v)
    d = np.stack([x, y, z], axis=-1)
    return d / np.linalg.norm(d, axis=-1, keepdims=True)


def octahedral_encode(d: np.ndarray) -> np.ndarray:
    """The inverse of octahedral_decode: uv (..., 2) of directions (..., 3)."""
    d = np.asarray(d, np.float64)
    d = d / np.abs(d).sum(axis=-1, keepdims=True)
    x, y, z = d[..., 0], d[..., 1], d[..., 2]
    sx, sy = np.where(x >= 0.0, 1.0, -1.0), np.where(y >= 0.0, 1.0, -1.0)
    u = np.where(z < 0.0, (1.0 - np.abs(y)) * sx, x)
    v = np.where(z < 0.0, (1.0 - np.abs(x)) * sy, y)
    return np.stack([u, v], axis=-1)


def octahedral_directions(k: int) -> np.ndarray:
    """(k, k, 3) directions of a k x k octahedral tile's texel centres, [row j, column i]."""
    c = 2.0 * (np.arange(k) + 0.5) / k - 1.0
    v, u = np.meshgrid(c, c, indexing="ij")
    return octahedral_decode(np.stack([u, v], axis=-1))


def octahedral_border(tiles: np.ndarray) -> np.ndarray:
    """Tiles (..., k, k, c) inside a one-texel border: (..., k + 2, k + 2, c). Crossing the square's
    edge u = 1 at height v lands on the octahedron at (1, -v) from inside (and likewise for the other
    edges), so each edge's border texel repeats the interior edge texel mirrored along that edge, and a
    corner repeats the interior's opposite corner (DDGI's rule)."""
    inner = np.asarray(tiles)
    k = inner.shape[-2]
    out = np.zeros((*inner.shape[:-3], k + 2, k + 2, inner.shape[-1]), inner.dtype)
    out[..., 1:-1, 1:-1, :] = inner
    out[..., 0, 1:-1, :] = inner[..., 0, ::-1, :]
    out[..., -1, 1:-1, :] = inner[..., -1, ::-1, :]
    out[..., 1:-1, 0, :] = inner[..., ::-1, 0, :]
    out[..., 1:-1, -1, :] = inner[..., ::-1, -1, :]
    out[..., 0, 0, :] = inner[..., -1, -1, :]
    out[..., 0, -1, :] = inner[..., -1, 0, :]
    out[..., -1, 0, :] = inner[..., 0, -1, :]
    out[..., -1, -1, :] = inner[..., 0, 0, :]
    return out


def cube_bilinear(grid: ProbeGrid, atlas: np.ndarray, n: int, directions: np.ndarray) -> np.ndarray:
    """Every probe's n x n cube-map atlas (the capture's tile layout) read at directions (d, 3) as the
    renderer reads it (probe.glsl's face_bilinear): the face of the major axis, bilinear within that
    face, clamped at its edges. Returns (P, d, c) in probe order p."""
    d = np.asarray(directions, np.float64)
    a = np.abs(d)
    axis = np.where((a[:, 0] >= a[:, 1]) & (a[:, 0] >= a[:, 2]), 0, np.where(a[:, 1] >= a[:, 2], 1, 2))
    face = 2 * axis + (d[np.arange(len(d)), axis] < 0.0)
    frames = FACE_FRAMES[face]                                               # (d, 3 vectors, 3)
    w = np.einsum("dk,dk->d", d, frames[:, 0])
    st = np.stack([np.einsum("dk,dk->d", d, frames[:, 1]), np.einsum("dk,dk->d", d, frames[:, 2])], -1)
    st = st / np.maximum(w, 1e-12)[:, None]
    uv = np.clip((st + 1.0) * (0.5 * n) - 0.5, 0.0, n - 1)
    i0 = np.floor(uv).astype(np.int64)
    i1 = np.minimum(i0 + 1, n - 1)
    f = uv - i0
    x0, y0 = _face_origin(grid, n, np.arange(grid.count)[:, None], face)
    src = np.asarray(atlas, np.float64)

    def at(ix, iy):
        return src[y0 + iy, x0 + ix]                                         # (P, d, c)

    fx, fy = f[:, 0][None, :, None], f[:, 1][None, :, None]
    return ((1 - fx) * (1 - fy) * at(i0[:, 0], i0[:, 1]) + fx * (1 - fy) * at(i1[:, 0], i0[:, 1])
            + (1 - fx) * fy * at(i0[:, 0], i1[:, 1]) + fx * fy * at(i1[:, 0], i1[:, 1]))


def octahedral_size(grid: ProbeGrid, k: int) -> tuple[int, int]:
    """(width, height) of an octahedral atlas of k x k tiles inside their borders."""
    nx, ny, nz = grid.dims
    return (k + 2) * nx, (k + 2) * ny * nz


def octahedral_atlas(grid: ProbeGrid, per_probe: np.ndarray) -> np.ndarray:
    """(P, k, k, c) tiles in probe order -> the atlas ((k + 2) ny nz, (k + 2) nx, c): each tile inside its
    border (octahedral_border), probe (ix, iy, iz) at tile (ix, iy + ny iz)."""
    nx, ny, nz = grid.dims
    tiles = octahedral_border(np.asarray(per_probe))
    k2, c = tiles.shape[1], tiles.shape[3]
    return tiles.reshape(nz, ny, nx, k2, k2, c).transpose(0, 1, 3, 2, 4, 5).reshape(nz * ny * k2, nx * k2, c)


def octahedral_irradiance(grid: ProbeGrid, coeffs: np.ndarray | None, irradiance: np.ndarray | None,
                          n: int, k: int = OCT_IRRADIANCE_TEXELS) -> np.ndarray:
    """The irradiance in DDGI's octahedral layout (octahedral_atlas of k x k tiles), W/m^2: from the SH
    (nz, ny, nx, 9, 3) when given, E = max(0, sum_i h_l A_l c_i Y_i(d)) exactly as the lookup evaluates it,
    else from the irradiance cube atlas of n x n faces read as the lookup reads it (cube_bilinear)."""
    dirs = octahedral_directions(k).reshape(-1, 3)
    if coeffs is not None:
        e = _sh_irradiance(grid, coeffs, dirs)
    else:
        e = cube_bilinear(grid, np.asarray(irradiance)[..., :3], n, dirs)
    return octahedral_atlas(grid, e.reshape(grid.count, k, k, 3))


def octahedral_moments(grid: ProbeGrid, moments: np.ndarray, k: int = OCT_MOMENT_TEXELS) -> np.ndarray:
    """The distance moments (mean m, mean square m^2, 0) in DDGI's octahedral layout (k x k tiles), read
    from the capture's moment atlas as the lookup reads it (cube_bilinear)."""
    m = cube_bilinear(grid, np.asarray(moments)[..., :2], grid.face_texels, octahedral_directions(k).reshape(-1, 3))
    m = np.concatenate([m, np.zeros_like(m[..., :1])], axis=-1)
    return octahedral_atlas(grid, m.reshape(grid.count, k, k, 3))


def layout(grid: ProbeGrid, origin_m, encoding: str, irradiance_texels: int, probes_off: list[int],
           files: dict[str, str], relocated: bool = False) -> dict:
    """The JSON description an engine needs to read the atlases (origin_m: the solve's frame in world
    space, the method's re-centring)."""
    nx, ny, nz = grid.dims
    return {
        "format": FORMAT, "version": VERSION, "encoding": encoding,
        "dims": [nx, ny, nz],
        "first_probe_m": [float(v) for v in np.asarray(grid.first_m) + np.asarray(origin_m)],
        "spacing_m": float(grid.spacing_m),
        "probe_index": ("p = ix + nx * (iy + ny * iz); probe (ix, iy, iz) at first_probe_m + (ix, iy, iz) * spacing_m "
                        "+ its offset (offsets)"),
        "relocated": bool(relocated),
        "faces": [{"face": f, "forward": FACE_FRAMES[f, 0].tolist(), "right": FACE_FRAMES[f, 1].tolist(),
                   "up": FACE_FRAMES[f, 2].tolist()} for f in range(6)],
        "texel_direction": ("face texel (i, j) of n x n looks along normalize(forward + s right + t up), "
                            "s = 2 (i + 0.5) / n - 1, t = 2 (j + 0.5) / n - 1"),
        "tiles_per_row": grid.tiles_per_row,
        "tile": ("probe p owns a 3n x 2n tile at texel (3 n (p % tiles_per_row), 2 n (p // tiles_per_row)); "
                 "face f's texel (i, j) at tile + (n (f % 3) + i, n (f // 3) + j)"),
        "rows": ("texel (x, y) counts y from the atlas's bottom row: in the EXR files it is pixel row "
                 "height - 1 - y (EXR row 0 is the top)"),
        "sh": {"file": files["sh"], "size": list(grid.sh_size),
               "texel": "coefficient c (sh.py order: 1, y, z, x, xy, yz, 3z^2-1, xz, x^2-y^2) of probe (ix, iy, iz) "
                        "at (c nx + ix, iy + ny iz)",
               "units": "L2 SH of arriving radiance, W/m^2/sr per colour, by direction of arrival",
               "lookup_irradiance": ("E(n) = max(0, sum_c h_l A_l c Y_c(n)) per colour, band l of c: A_l = (pi, "
                                     f"2 pi / 3, pi / 4), h_l = {list(sh.IRRADIANCE_WINDOW_L2)} (the renderer's "
                                     "deringing window; h_l = 1 is the plain clamped-cosine convolution)")},
        "irradiance": {"file": files["irradiance"], "face_texels": irradiance_texels,
                       "size": list(grid.tiled_size(irradiance_texels)),
                       "units": "irradiance W/m^2 on a surface whose normal is the texel's direction; "
                                "Cycles' Diffuse Indirect = E / pi"},
        "moments": {"file": files["moments"], "face_texels": grid.face_texels, "size": list(grid.atlas_size),
                    "units": "R: mean distance (m), G: mean square distance (m^2) to the surfaces seen; B: 0"},
        "offsets": {"file": files["offsets"], "size": list(grid.state_size),
                    "texel": "probe (ix, iy, iz) at (ix, iy + ny iz)",
                    "units": "RGB: the probe's move off its grid position (m, world axes); within 0.45 spacing "
                             "per axis"},
        "octahedral": {
            "irradiance": {"file": files["irradiance_oct"], "texels": OCT_IRRADIANCE_TEXELS,
                           "size": list(octahedral_size(grid, OCT_IRRADIANCE_TEXELS)),
                           "units": "as irradiance"},
            "moments": {"file": files["moments_oct"], "texels": OCT_MOMENT_TEXELS,
                        "size": list(octahedral_size(grid, OCT_MOMENT_TEXELS)), "units": "as moments"},
            "tile": ("probe (ix, iy, iz) owns a (k + 2) x (k + 2) tile at texel ((k + 2) ix, (k + 2) (iy + ny iz)); "
                     "its interior texel (i, j) of k x k at tile + (1 + i, 1 + j), the rest a one-texel border"),
            "texel_direction": ("interior texel (i, j) at u = 2 (i + 0.5) / k - 1, v = 2 (j + 0.5) / k - 1 looks along "
                                "normalize(u, v, 1 - |u| - |v|) where |u| + |v| <= 1, else "
                                "normalize((1 - |v|) sign u, (1 - |u|) sign v, 1 - |u| - |v|) (sign 0 = +1)"),
            "border": ("each edge texel repeats the interior texel beside it mirrored along that edge, each corner "
                       "the interior's opposite corner: bilinear filtering across an edge stays on the sphere"),
        },
        "probes_off": [int(p) for p in probes_off],
        "lookup": ("docs/PROBES.md: weight the 8 probes of the grid cell around p + normal_bias * spacing * n "
                   "(cells and trilinear weights from the grid positions) by trilinear x back-face x Chebyshev "
                   "visibility (moments; both from the offset positions), skip probes_off, renormalise, "
                   "clamp at 0"),
    }
