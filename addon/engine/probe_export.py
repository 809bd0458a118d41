"""The probe volume for engines (`bake --target probes`; docs/BAKE.md, docs/PROBES.md): what method
`probes` solved, as arrays in a documented layout. numpy only; the bridge writes the files.

An engine gets four textures and a layout:
- `sh`: the L2 SH of the radiance arriving at each probe (W/m^2/sr, by direction of arrival), the
  paper's nine coefficients per colour (sh.py's basis and order). With the SH encoding these are the
  solve's own; with the irradiance encoding they are the irradiance cube maps projected to SH and
  divided by the cosine lobe's band factors (E = A_l L per band, so L = E / A_l: exact for a field of
  bands 0..2, a least-squares fit otherwise).
- `irradiance`: each probe's irradiance cube map E(n) (W/m^2) at IRRADIANCE_TEXELS^2 normals a face, in
  the capture's tile layout. With the SH encoding, E(n) = max(0, sum_i A_l c_i Y_i(n)), what the
  renderer's lookup evaluates; with the irradiance encoding, the solve's own maps.
- `moments`: the mean and mean square of the distance (m, m^2) from each probe to what its capture
  texels see (the lookup's Chebyshev visibility), at the capture's face_texels^2 a face.
- `offsets`: each probe's move off its grid position (m; ProbesConfig.relocate, else 0), one texel per
  probe in the state's layout: the probe sits at its grid position + offset, and the moments are
  distances from there.
Atlases are (h, w, 3) float32 with row 0 the texture's first (bottom) row, as the GPU holds them.
"""

from __future__ import annotations

import numpy as np

from . import sh
from .probe_grid import FACE_FRAMES, SH_COEFFS, ProbeGrid, texel_directions, texel_solid_angles

FORMAT = "bounce-probes"
VERSION = 2  # 2: the offsets (relocated probes)


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


def _face_texels(grid: ProbeGrid, n: int) -> tuple[np.ndarray, np.ndarray]:
    """Atlas rows and columns (P, 6, n, n) of every probe's face texels in an n x n tiled atlas."""
    cols = grid.tiles_per_row
    p = np.arange(grid.count)[:, None, None, None]
    f = np.arange(6)[None, :, None, None]
    j = np.arange(n)[None, None, :, None]
    i = np.arange(n)[None, None, None, :]
    x = 3 * n * (p % cols) + n * (f % 3) + i
    y = 2 * n * (p // cols) + n * (f // 3) + j
    return np.broadcast_to(y, (grid.count, 6, n, n)), np.broadcast_to(x, (grid.count, 6, n, n))


def irradiance_from_sh(grid: ProbeGrid, coeffs: np.ndarray, n: int) -> np.ndarray:
    """The irradiance atlas (grid.tiled_size(n) as (h, w, 3), W/m^2) of SH radiance (nz, ny, nx, 9, 3):
    E at every face texel's centre normal, clamped at 0, as the lookup evaluates it."""
    lobe = sh.cosine_lobe_l2(texel_directions(n).reshape(-1, 3))                  # (6 n n, 9)
    per_probe = np.asarray(coeffs, np.float64).reshape(grid.count, SH_COEFFS, 3)  # probe order p
    e = np.maximum(np.einsum("pck,dc->pdk", per_probe, lobe), 0.0).reshape(grid.count, 6, n, n, 3)
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
               "units": "L2 SH of arriving radiance, W/m^2/sr per colour, by direction of arrival"},
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
        "probes_off": [int(p) for p in probes_off],
        "lookup": ("docs/PROBES.md: weight the 8 probes of the grid cell around p + normal_bias * spacing * n "
                   "(cells and trilinear weights from the grid positions) by trilinear x back-face x Chebyshev "
                   "visibility (moments; both from the offset positions), skip probes_off, renormalise, "
                   "clamp at 0"),
    }
