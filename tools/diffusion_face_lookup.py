"""A design alternative for `diffusion`'s reconstruction, measured: reading a pixel's irradiance from the
flux its cells absorbed by the face the light came through, instead of from one side of each cell's one
plane (docs/DIFFUSION.md, "Coarse cells in real scenes").

    .venv/bin/python tools/diffusion_face_lookup.py BLEND --reference REF/indirect.exr \
        [--set diffusion.grid_cells=64 ...]

One bounce, one propagation of every emitter (emitter classes off) on one grid (far field off): the
far field's grid already absorbs by face, the fine grid's classes would need sorting by face too. The
method runs with those settings and its image is the *sides* reading; the same emitters are then
propagated again with the absorbed flux kept by face (the far grid's `diffusion_propagate` mode), and
`face_lookup` reads them. Prints one JSON object: rel_rmse_8 and bias (mean over the covered pixels
against Cycles') of both readings, and the two fields' total flux over each other (1: the same light).

The reading by face: light that crossed face f travels along d_f, so it lit the cell's surfaces facing
-d_f. Over the faces whose source neighbour (the cell light comes from) is empty and in the grid (an
occupied cell sends light only to empty ones), with weights w_f = max(0, -d_f . n)^2 (they sum to 1
over the faces opposing n), the irradiance is sum w_f flux_f / (h^2 sum w_f block_f): under a uniform
radiance L each face's absorbed flux is block_f pi L h^2, so every normal reads pi L. The cells are
blended as the sides lookup blends them, each by its trilinear weight times sum w_f block_f.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "tools"))

from diffusion_dark_pixels import diffusion_at_reference, parse_args  # noqa: E402

from addon.engine.diffusion_reference import DIRECTIONS, lookup_corners  # noqa: E402

ONE_PROPAGATION = ["diffusion.cone_fields=false",
                   "diffusion.emitter_class_passes=false", "diffusion.far_field=false"]


def face_lookup(points_m: np.ndarray, normals: np.ndarray, origin_m, cell_m: float, block: np.ndarray,
                faces: np.ndarray) -> np.ndarray:
    """Irradiance / pi (rgb) at points (n, 3) with unit normals (n, 3) from `faces` (z, y, x, 6, 3): the
    flux (W) each cell absorbed by the face it came through (0..5: +x -x +y -y +z -z, the direction the
    light travelled), `block` the cells (diffusion/cell.glsl: xyz per-axis absorbed share, w > 0
    occupied). 0 where no cell near has a face the point's surface could be lit through."""
    dims = np.array(block.shape[:3][::-1])
    facing = np.maximum(0.0, -(normals @ DIRECTIONS.T)) ** 2  # (n, 6)
    steps = DIRECTIONS.astype(int)
    num = np.zeros((len(points_m), 3))
    den = np.zeros(len(points_m))
    points_cells = (points_m - np.asarray(origin_m)) / cell_m
    for cc, t, inside in lookup_corners(points_cells, dims):  # as diffusion/lookup.comp.glsl reads them
        b = block[cc[:, 2], cc[:, 1], cc[:, 0]]
        source = cc[:, None, :] - steps[None]  # (n, 6, 3): the cell light through face f came from
        source_inside = np.all((source >= 0) & (source < dims), axis=2)
        sc = np.clip(source, 0, dims - 1)
        reached = source_inside & (block[sc[..., 2], sc[..., 1], sc[..., 0], 3] <= 0)
        w = facing * reached
        seen = (w * np.repeat(b[:, :3], 2, axis=1)).sum(axis=1)  # sum w_f block_f
        flux = np.einsum("nf,nfc->nc", w, faces[cc[:, 2], cc[:, 1], cc[:, 0]])
        ok = inside & (b[:, 3] > 0) & (seen > 1e-6)
        e = flux / (cell_m**2 * np.where(ok, seen, 1.0))[:, None]
        num += np.where(ok, t * seen, 0.0)[:, None] * e
        den += np.where(ok, t * seen, 0.0)
    return np.where(den[:, None] > 0.0, num / np.where(den > 0.0, den, 1.0)[:, None], 0.0) / np.pi


def main() -> int:
    args = parse_args(__doc__.splitlines()[0])
    from addon.engine import metrics
    from addon.engine.methods.diffusion import steps_per_bounce
    from addon.engine.passes import diffusion_inject, diffusion_propagate

    be, method, reference = diffusion_at_reference(args.blend, args.reference, ONE_PROPAGATION + args.sets)
    sides = method.run().images["indirect"][..., :3].astype(np.float64)

    grid, cells = method.grid, method.cells
    diffusion_inject.emit(be, method.injected, cells, method.snapshots[0], grid, atlas=method.atlas)
    by_face = diffusion_propagate.faces(be, grid)
    for i in range(steps_per_bounce(method.diffusion_config, grid, 1)):
        diffusion_propagate.run(be, method.snapshots[i % 2], method.snapshots[(i + 1) % 2], by_face, cells, grid,
                                first_step=i == 0, transfer=method.diffusion_config.transfer)
    packed = np.concatenate([be.read(by_face[f"acc_{i}"]) for i in range(5)], axis=-1).astype(np.float64)
    faces = packed[..., :18].reshape(*packed.shape[:3], 6, 3)  # diffusion/faces.glsl: number 3 f + channel
    sides_flux = sum(be.read(method.accumulated[k])[..., :3].astype(np.float64).sum()
                     for k in ("flux_plus", "flux_minus"))

    # The G-buffer is read with GL's row 0 at the bottom; the method's image has row 0 at the top.
    position, normal = (be.read(method.gbuf[k])[::-1] for k in ("position", "normal"))
    covered = position[..., 3] > 0
    n = normal[covered][:, :3].astype(np.float64)
    n /= np.maximum(np.linalg.norm(n, axis=1, keepdims=True), 1e-12)
    by_faces = np.zeros_like(sides)
    by_faces[covered] = face_lookup(position[covered][:, :3].astype(np.float64), n, grid.origin_m,
                                    grid.cell_size_m, be.read(cells["cell_block"]), faces)

    def scores(image):
        return {"rel_rmse_8": round(metrics.rel_rmse_8(image, reference), 3),
                "bias": round(float(image[covered].mean() / reference[covered].mean()), 3)}
    print(json.dumps({"sides": scores(sides), "faces": scores(by_faces),
                      "flux_faces_over_sides": round(float(faces.sum() / sides_flux), 6)}))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
