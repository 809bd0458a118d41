"""A regular grid of cubic cells fitted to the scene's occupied bounds (non-cubic where the scene is flat).

World -> grid: g = (p - origin_m) / cell_size_m; cell (i, j, k) spans [i, i+1) x [j, j+1) x [k, k+1).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Grid:
    origin_m: np.ndarray
    cell_size_m: float
    dims: tuple[int, int, int]

    @classmethod
    def fit(cls, lo: np.ndarray, hi: np.ndarray, max_cells: int, pad_cells: float = 1.5) -> Grid:
        """Cells of one size so the longest side of the bounds (plus `pad_cells` on each side) gets
        `max_cells`; the other axes get as many as they need (at least 1). The half-cell in the default
        padding puts geometry at the bounds (outer walls) mid-cell, not on a cell boundary where float
        rounding at another scene scale would pick the neighbouring cell."""
        lo, hi = np.asarray(lo, np.float64), np.asarray(hi, np.float64)
        extent = np.maximum(hi - lo, 1e-6)
        cell = float(extent.max()) / (max_cells - 2.0 * pad_cells)
        dims = np.minimum(np.ceil(extent / cell + 2.0 * pad_cells).astype(int), max_cells)
        dims = np.maximum(dims, 1)
        center = (lo + hi) / 2.0
        origin = center - dims * cell / 2.0
        return cls(origin, cell, tuple(int(d) for d in dims))

    def same_cells(self, other: Grid | None) -> bool:
        """The same cells in the same place (dataclass == cannot compare the origin arrays)."""
        return (other is not None and self.dims == other.dims and self.cell_size_m == other.cell_size_m
                and np.array_equal(self.origin_m, other.origin_m))

    def to_grid(self, p_m: np.ndarray) -> np.ndarray:
        return (np.asarray(p_m, np.float64) - self.origin_m) / self.cell_size_m

    @property
    def extent_m(self) -> np.ndarray:
        return np.asarray(self.dims, np.float64) * self.cell_size_m
