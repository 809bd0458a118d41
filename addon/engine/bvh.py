"""A bounding-volume hierarchy over triangles, for exact shadow rays on the GPU. Pure numpy.

Why: a shadow map names, per texel, the surface nearest its light, so a ray slanted against the map's
axis is tested against the wrong triangles: the sky pass's rays through a window let light through the
thin halves of wall quads and past box corners no texel centre sees (docs/DIRECT.md, "What limits the
sky pass"). Testing each ray against the triangles themselves is exact; the hierarchy makes that
logarithmic in the triangle count.

Layout: a complete binary tree in heap order (node i's children 2i + 1 and 2i + 2) over the triangles
sorted by the Morton code of their centroids, `LEAF_TRIANGLES` per leaf. Building it is a sort and a
reduction per level (no per-node Python: Sponza's 67 k triangles take tens of milliseconds); the tree's
shape ignores the geometry, which costs some traversal steps against a surface-area build, not
exactness. Leaves past the last triangle are empty (their bounds inverted: no ray enters them).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

LEAF_TRIANGLES = 4
MORTON_BITS = 10  # per axis: a 1024^3 lattice over the bounds


@dataclass(frozen=True)
class Bvh:
    """`order`: the triangles' indices in leaf order (leaf j holds order[j LEAF : (j + 1) LEAF]);
    `lo`, `hi`: (nodes, 3) bounds in heap order, nodes = 2 leaves - 1; `leaves`: a power of 2."""

    order: np.ndarray
    lo: np.ndarray
    hi: np.ndarray
    leaves: int

    @property
    def nodes(self) -> int:
        return 2 * self.leaves - 1


def _spread_bits(v: np.ndarray) -> np.ndarray:
    """10-bit integers -> their bits at every third position (for interleaving x, y, z)."""
    v = v.astype(np.uint32) & 0x3FF
    v = (v | (v << 16)) & 0x030000FF
    v = (v | (v << 8)) & 0x0300F00F
    v = (v | (v << 4)) & 0x030C30C3
    return (v | (v << 2)) & 0x09249249


def morton_codes(points: np.ndarray) -> np.ndarray:
    """(n, 3) points -> their Morton codes on a 2^MORTON_BITS lattice over the points' bounds."""
    lo, hi = points.min(axis=0), points.max(axis=0)
    cells = (1 << MORTON_BITS) - 1
    q = np.floor((points - lo) / np.maximum(hi - lo, 1e-30) * cells + 0.5).astype(np.int64)
    q = np.clip(q, 0, cells)
    return (_spread_bits(q[:, 0]) << 2) | (_spread_bits(q[:, 1]) << 1) | _spread_bits(q[:, 2])


def build(triangles_m: np.ndarray) -> Bvh:
    """The hierarchy of (n, 3, 3) triangle corners (m); n >= 0."""
    triangles_m = np.asarray(triangles_m, np.float64).reshape(-1, 3, 3)
    n = len(triangles_m)
    leaves = 1
    while leaves * LEAF_TRIANGLES < n:
        leaves *= 2
    order = np.argsort(morton_codes(triangles_m.mean(axis=1)), kind="stable") if n else np.zeros(0, np.int64)
    # Leaf bounds: each leaf's triangles' corners; empty slots hold +inf / -inf, so they never widen a box.
    slots = np.full((leaves * LEAF_TRIANGLES, 3, 3), np.nan)
    slots[:n] = triangles_m[order]
    slots = slots.reshape(leaves, LEAF_TRIANGLES * 3, 3)
    with np.errstate(invalid="ignore"):
        level_lo = np.where(np.isnan(slots), np.inf, slots).min(axis=1)
        level_hi = np.where(np.isnan(slots), -np.inf, slots).max(axis=1)
    lo, hi = [level_lo], [level_hi]
    while len(level_lo) > 1:  # each level up: the union of child pairs
        level_lo = np.minimum(level_lo[0::2], level_lo[1::2])
        level_hi = np.maximum(level_hi[0::2], level_hi[1::2])
        lo.append(level_lo)
        hi.append(level_hi)
    # Heap order: the root first, then each level left to right (levels were made leaves first).
    return Bvh(order=order, lo=np.concatenate(lo[::-1]), hi=np.concatenate(hi[::-1]), leaves=leaves)


NODE_ROW = 1024  # nodes per row of the node table (2 texels each)


def node_table(tree: Bvh) -> np.ndarray:
    """(rows, 2 NODE_ROW, 4) float32: node i's low corner at texel (2 (i % NODE_ROW), i // NODE_ROW), its
    high corner beside it. A node over no triangle (infinite bounds) is stored as low 1, high -1: the
    traversal skips a node whose low x exceeds its high x."""
    rows = max(1, -(-tree.nodes // NODE_ROW))
    table = np.zeros((rows * NODE_ROW, 2, 4), np.float32)
    empty = ~np.all(np.isfinite(tree.lo), axis=1)
    table[:tree.nodes, 0, :3] = np.where(empty[:, None], 1.0, tree.lo)
    table[:tree.nodes, 1, :3] = np.where(empty[:, None], -1.0, tree.hi)
    return table.reshape(rows, NODE_ROW * 2, 4)


def leaf_triangles(tree: Bvh, triangles_m: np.ndarray) -> np.ndarray:
    """(leaves LEAF_TRIANGLES, 3, 3): the triangles in leaf order, empty slots all-zero (no area: no ray
    crosses them), for rsm.occluder_table's layout."""
    out = np.zeros((tree.leaves * LEAF_TRIANGLES, 3, 3))
    out[:len(tree.order)] = np.asarray(triangles_m, np.float64).reshape(-1, 3, 3)[tree.order]
    return out


def occluded(tree: Bvh, triangles_m: np.ndarray, q: np.ndarray, w: np.ndarray, s_min: float,
             s_max: float = np.inf) -> bool:
    """Whether q + s w crosses a triangle for s_min < s < s_max, by the hierarchy: the reference the
    shader's traversal (common/bvh.glsl) is tested against."""
    inv = 1.0 / np.where(np.abs(w) < 1e-30, 1e-30, w)
    stack = [0]
    first_leaf = tree.leaves - 1
    while stack:
        i = stack.pop()
        if not tree.lo[i][0] <= tree.hi[i][0]:
            continue  # over no triangle
        t0, t1 = (tree.lo[i] - q) * inv, (tree.hi[i] - q) * inv
        near = np.max(np.minimum(t0, t1))
        far = np.min(np.maximum(t0, t1))
        if not (near <= far and far > s_min and near < s_max):
            continue
        if i < first_leaf:
            stack += [2 * i + 1, 2 * i + 2]
            continue
        leaf = i - first_leaf
        for t in tree.order[leaf * LEAF_TRIANGLES:(leaf + 1) * LEAF_TRIANGLES]:
            if segment_crosses(triangles_m[t], q, w, s_min, s_max):
                return True
    return False


def segment_crosses(tri: np.ndarray, q: np.ndarray, w: np.ndarray, s_min: float, s_max: float) -> bool:
    """Moller and Trumbore's test of q + s w against one triangle (either side), s_min < s < s_max."""
    a, e1, e2 = tri[0], tri[1] - tri[0], tri[2] - tri[0]
    h = np.cross(w, e2)
    det = e1 @ h
    if abs(det) <= 1e-7 * np.linalg.norm(e1) * np.linalg.norm(e2):
        return False
    from_a = q - a
    u = from_a @ h / det
    g = np.cross(from_a, e1)
    v = w @ g / det
    s = e2 @ g / det
    return bool(u >= 0 and v >= 0 and u + v <= 1 and s_min < s < s_max)
