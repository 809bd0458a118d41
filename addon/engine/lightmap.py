"""Bake helpers in numpy (no GPU, no bpy): seam dilation, safe output names, shard selection, UV checks.

Images here are (h, w, c) float arrays with a boolean coverage mask (h, w); the orientation does not
matter to any of these functions.
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np

from .errors import ConfigError
from .passes.bake_gbuffer import CONSERVATIVE_COVERAGE

PASSES = ("indirect", "direct", "combined")
TARGETS = ("image", "vertex-colors", "volume", "probes")
# Targets baked once per scene, not per object, and the method each bakes: the LPV's SH grid, the probes.
VOLUME_TARGETS = {"volume": "lpv", "probes": "probes"}


def dilate(image: np.ndarray, covered: np.ndarray, iterations: int = 16) -> tuple[np.ndarray, np.ndarray]:
    """Fill empty texels from covered neighbours, `iterations` rings deep (seam padding).

    Each iteration, every empty texel with at least one filled texel among its 8 neighbours becomes the
    mean of those neighbours (as filled before the iteration); covered texels never change. Returns
    (image, filled mask). Exact: texel values are means of their ring-(k-1) neighbours, nothing else.
    """
    img = np.array(image, dtype=np.float64, copy=True)
    filled = np.array(covered, dtype=bool, copy=True)
    h, w = filled.shape
    for _ in range(max(0, int(iterations))):
        if filled.all() or not filled.any():
            break
        pad_v = np.zeros((h + 2, w + 2) + img.shape[2:])
        pad_m = np.zeros((h + 2, w + 2))
        pad_v[1:-1, 1:-1] = np.where(filled[..., None], img, 0.0) if img.ndim == 3 else np.where(filled, img, 0.0)
        pad_m[1:-1, 1:-1] = filled
        total = np.zeros_like(img)
        n = np.zeros((h, w))
        for dy in (-1, 0, 1):
            for dx in (-1, 0, 1):
                if dy == 0 and dx == 0:
                    continue
                total += pad_v[1 + dy:h + 1 + dy, 1 + dx:w + 1 + dx]
                n += pad_m[1 + dy:h + 1 + dy, 1 + dx:w + 1 + dx]
        grow = ~filled & (n > 0)
        if not grow.any():
            break
        nn = n[grow][:, None] if img.ndim == 3 else n[grow]
        img[grow] = total[grow] / nn
        filled = filled | grow
    return img.astype(np.asarray(image).dtype, copy=False), filled


IMAGE_SIZE_TEXELS = 512  # a lightmap's side when none is given
SUPERSAMPLE_MAX = 8  # sub-texels per texel side a bake takes at most (--supersample)


def block_mean(values: np.ndarray, factor: int) -> np.ndarray:
    """(h * factor, w * factor, 4) sub-texels (rgb, alpha = coverage: 1 where the surface covers the
    sub-texel's centre, CONSERVATIVE_COVERAGE where it only touches its square, 0 elsewhere) -> (h, w, 4):
    per texel the mean of its factor x factor sub-texels whose centres are covered, else (a texel the
    surface only grazes) of those it touches; alpha 1, CONSERVATIVE_COVERAGE or 0 (rgb 0) alike.

    Why: Cycles' bake gives a texel the mean light over its footprint (its samples jitter over it); a
    texel read at its centre alone takes a sharp shadow edge across it as all or nothing. A touched
    sub-texel stands at its surface's very edge (the nearest point to its centre), where the surface
    meets another or is hidden by it: at the end face of window-sky's SouthWall, pressed against the
    WestWall, such sub-texels read the sky past that wall's edge (Cycles: 0). factor 1 returns the
    values as they are."""
    if factor == 1:
        return values
    hf, wf, c = values.shape
    if hf % factor or wf % factor:
        raise ValueError(f"a {wf} x {hf} image does not split into {factor} x {factor} blocks")
    blocks = (hf // factor, factor, wf // factor, factor)
    alpha = values[..., 3].reshape(blocks)
    centred = alpha > 0.5 * (1.0 + CONSERVATIVE_COVERAGE)
    touched = alpha > 0.5
    has_centred = centred.any(axis=(1, 3), keepdims=True)
    weight = np.where(has_centred, centred, touched)
    total = np.where(weight[..., None], values[..., :3].reshape(*blocks, 3), 0.0).sum(axis=(1, 3))
    count = weight.sum(axis=(1, 3))
    rgb = total / np.maximum(count, 1)[..., None]
    cover = np.where(has_centred[:, 0, :, 0], 1.0, np.where(count > 0, CONSERVATIVE_COVERAGE, 0.0))
    return np.concatenate([rgb, cover[..., None]], axis=2).astype(values.dtype)


def check_supersample(factor: int, size: int) -> int:
    """The sub-texels per texel side, checked: 1..SUPERSAMPLE_MAX, and size x factor within the largest
    lightmap side (8192)."""
    if not 1 <= factor <= SUPERSAMPLE_MAX:
        raise ConfigError(f"--supersample must be in 1..{SUPERSAMPLE_MAX}, got {factor}")
    if size * factor > 8192:
        raise ConfigError(f"--size {size} x --supersample {factor} = {size * factor} texels a side: more than "
                          "8192; lower one of them")
    return factor


_UNSAFE = re.compile(r"[^A-Za-z0-9._-]+")


def safe_name(name: str) -> str:
    """A file-name stem from an object name: only letters, digits, '.', '_' and '-'; path separators,
    '..' and leading dots cannot survive, so the file stays inside the output directory."""
    stem = _UNSAFE.sub("_", name)
    stem = re.sub(r"\.{2,}", "_", stem).strip("._ -")
    return stem[:120] or "object"


def output_path(out_dir: Path, object_name: str, pass_name: str, taken: set[str] | None = None) -> Path:
    """DIR/<safe name>_<pass>.exr, de-duplicated against `taken` (names that sanitise alike get _2, _3);
    raises ConfigError if the result would not lie directly inside out_dir (it cannot: belt and braces)."""
    stem = f"{safe_name(object_name)}_{pass_name}"
    candidate, k = stem, 2
    while taken is not None and candidate.lower() in taken:
        candidate, k = f"{stem}_{k}", k + 1
    if taken is not None:
        taken.add(candidate.lower())
    root = Path(out_dir).resolve()
    path = (root / f"{candidate}.exr").resolve()
    if path.parent != root:
        raise ConfigError(f"object name {object_name!r} would write outside {out_dir}")
    return path


def parse_shard(text: str | None) -> tuple[int, int]:
    """'i/n' -> (i, n) with 0 <= i < n; None -> (0, 1)."""
    if text is None:
        return 0, 1
    m = re.fullmatch(r"\s*(\d+)\s*/\s*(\d+)\s*", text)
    if not m or int(m.group(2)) < 1 or int(m.group(1)) >= int(m.group(2)):
        raise ConfigError(f"--shard must be i/n with 0 <= i < n, got {text!r}")
    return int(m.group(1)), int(m.group(2))


def shard(names, index: int, count: int) -> list[str]:
    """Every count-th name of the sorted names, starting at index: shards are disjoint and cover all."""
    return sorted(names)[index::count]


def uv_problems(uv: np.ndarray, positions: np.ndarray) -> list[str]:
    """Warnings about a (n, 3, 2) UV layout of (n, 3, 3) world triangles: zero-area UV triangles (they get
    no texels), UVs outside 0..1 (they fall off the image)."""
    notes = []
    e1, e2 = uv[:, 1] - uv[:, 0], uv[:, 2] - uv[:, 0]
    uv_area = 0.5 * np.abs(e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0])
    world_area = 0.5 * np.linalg.norm(np.cross(positions[:, 1] - positions[:, 0], positions[:, 2] - positions[:, 0]),
                                      axis=1)
    zero = (uv_area <= 1e-12) & (world_area > 0)
    if zero.any():
        notes.append(f"{int(zero.sum())} of {len(uv)} triangles have zero UV area (not baked)")
    outside = np.any((uv < -1e-6) | (uv > 1 + 1e-6), axis=(1, 2))
    if outside.any():
        notes.append(f"{int(outside.sum())} of {len(uv)} triangles have UVs outside 0..1 (clipped)")
    return notes


def check_choice(value: str, choices: tuple[str, ...], what: str) -> str:
    if value not in choices:
        raise ConfigError(f"{what} must be one of {', '.join(choices)}, got {value!r}")
    return value
