"""Image error metrics (ARCHITECTURE.md section 6). numpy only: tests, CLI and benchmarks share them.

Conventions for every function here:
- `a` is the image under test, `b` the reference; both (h, w) or (h, w, c). Only the first three
  channels (RGB) are used, so an alpha channel is ignored; (h, w) images are one channel.
- `mask` is an (h, w) bool array (True = pixel counts) or None (all pixels). Means run over masked
  pixels and the RGB channels together.
- A value that is undefined (no masked pixel, or mean(b) <= 0 so nothing can be relative to it) is
  returned as None, never NaN or inf; `compare` says why in its "note".
"""

from __future__ import annotations

import math

import numpy as np

from .errors import BackendUnavailable, ConfigError

BLOCK = 8


def _prepare(a, b, mask):
    a = np.asarray(a, dtype=np.float64)
    b = np.asarray(b, dtype=np.float64)
    if a.ndim == 2:
        a = a[:, :, None]
    if b.ndim == 2:
        b = b[:, :, None]
    a, b = a[:, :, :3], b[:, :, :3]
    if a.shape != b.shape:
        raise ConfigError(f"images differ in size: {a.shape[1]}x{a.shape[0]}x{a.shape[2]} vs "
                          f"{b.shape[1]}x{b.shape[0]}x{b.shape[2]} (width x height x channels)")
    if mask is None:
        mask = np.ones(a.shape[:2], dtype=bool)
    mask = np.asarray(mask, dtype=bool)
    if mask.shape != a.shape[:2]:
        raise ConfigError(f"mask shape {mask.shape} does not match image {a.shape[:2]}")
    return a, b, mask


def _rel_rmse_weighted(a, b, w):
    """sqrt(sum w (a-b)^2 / sum w) / (sum w b / sum w), over RGB; w is (h, w) weights >= 0."""
    wsum = w.sum() * a.shape[2]
    if wsum <= 0:
        return None
    mean_b = (w[:, :, None] * b).sum() / wsum
    if not mean_b > 0:
        return None
    return float(math.sqrt((w[:, :, None] * (a - b) ** 2).sum() / wsum) / mean_b)


def rel_rmse(a, b, mask=None) -> float | None:
    """sqrt(mean((a-b)^2)) / mean(b) over masked pixels and RGB channels; None if undefined."""
    a, b, mask = _prepare(a, b, mask)
    return _rel_rmse_weighted(a, b, mask.astype(np.float64))


def box_average(img, mask, block: int = BLOCK):
    """Per-block means of the masked pixels: returns (means (H, W, c), counts (H, W)).

    Blocks are aligned at pixel (0, 0) (top left); the last row/column of blocks may be partial.
    A block's mean uses only its masked pixels; blocks without any have count 0 (and mean 0).
    """
    h, w, c = img.shape
    hb, wb = -(-h // block), -(-w // block)
    pad = ((0, hb * block - h), (0, wb * block - w))
    m = np.pad(mask.astype(np.float64), pad)
    x = np.pad(img, (*pad, (0, 0))) * m[:, :, None]
    sums = x.reshape(hb, block, wb, block, c).sum(axis=(1, 3))
    counts = m.reshape(hb, block, wb, block).sum(axis=(1, 3))
    means = sums / np.maximum(counts, 1)[:, :, None]
    return means, counts


def rel_rmse_8(a, b, mask=None, block: int = BLOCK) -> float | None:
    """rel_rmse of the 8x8 box averages: the low-frequency error a preview is judged by.

    How the mask enters: each block averages only its masked pixels (in a and b alike), and each
    block is then weighted by its number of masked pixels. So background never leaks into a block,
    a block with 1 masked pixel counts 1/64 of a full one (it is as noisy as a pixel), the
    denominator equals mean(b) over masked pixels (same as rel_rmse), and with block = 1 the result
    is exactly rel_rmse.
    """
    a, b, mask = _prepare(a, b, mask)
    ma, counts = box_average(a, mask, block)
    mb, _ = box_average(b, mask, block)
    return _rel_rmse_weighted(ma, mb, counts)


def _noisy_blocks(checks, mask, block: int):
    """Per block of the unbiased noisy images `checks` (k >= 2, independent seeds): their mean C, the
    estimate of var(C) from their spread, s^2 = sum (C_i - C)^2 / (k (k - 1)) (its expectation is var(C)),
    the blocks' counts, and the first image prepared (for its shape)."""
    if len(checks) < 2:
        raise ConfigError(f"the noise of images needs at least 2 of them, got {len(checks)}")
    prepared = [_prepare(c, checks[0], mask) for c in checks]
    mask = prepared[0][2]
    means = np.stack([box_average(p[0], mask, block)[0] for p in prepared])
    counts = box_average(prepared[0][0], mask, block)[1]
    k = len(checks)
    mc = means.mean(axis=0)
    return mc, ((means - mc) ** 2).sum(axis=0) / (k * (k - 1)), counts, mask


def rel_noise_8(checks, mask=None, block: int = BLOCK) -> float | None:
    """The relative noise of the mean of `checks` (unbiased renders with independent seeds) in
    rel_rmse_8's terms: its expected rel_rmse_8 against what they converge to, from their spread alone."""
    mc, spread, counts, _ = _noisy_blocks(checks, mask, block)
    wsum = counts.sum() * mc.shape[2]
    if wsum <= 0:
        return None
    mean_c = float((counts[:, :, None] * mc).sum() / wsum)
    return math.sqrt(float((counts[:, :, None] * spread).sum() / wsum)) / mean_c if mean_c > 0 else None


def rel_rmse_8_against_noisy(a, checks, mask=None, block: int = BLOCK) -> float | None:
    """rel_rmse_8 of `a` against what the unbiased noisy images `checks` converge to, estimated from the
    images alone; None where undefined.

    `checks`: k >= 2 renders of the same image by an unbiased estimator with independent seeds (Cycles at
    a few samples). Per block and channel, with C the checks' mean and T its expectation: E[(A - C)^2] =
    (A - T)^2 + var(C), and var(C) is estimated without bias from the checks' spread (_noisy_blocks). So
    D^2 - N^2 (D: A's rel_rmse_8 against C; N: rel_noise_8, both weighted as rel_rmse_8 weighs its blocks)
    estimates A's squared error against T without bias, however noisy the checks: a check need not be
    more accurate than the image it judges, only precise enough for that difference. Clamped at 0 (the
    difference can fall below it where A is nearly exact)."""
    mc, spread, counts, mask = _noisy_blocks(checks, mask, block)
    ma = box_average(_prepare(a, checks[0], mask)[0], mask, block)[0]
    wsum = counts.sum() * mc.shape[2]
    if wsum <= 0:
        return None
    mean_c = float((counts[:, :, None] * mc).sum() / wsum)
    if not mean_c > 0:
        return None
    d2 = float((counts[:, :, None] * (ma - mc) ** 2).sum() / wsum)
    n2 = float((counts[:, :, None] * spread).sum() / wsum)
    return math.sqrt(max(d2 - n2, 0.0)) / mean_c


def bias(a, b, mask=None) -> float | None:
    """mean(a) / mean(b) over masked pixels and RGB channels; None if undefined."""
    a, b, mask = _prepare(a, b, mask)
    if not mask.any():
        return None
    mean_b = b[mask].mean()
    return float(a[mask].mean() / mean_b) if mean_b > 0 else None


def compare(a, b, mask=None) -> dict:
    """All metrics of `a` against the reference `b`: rel_rmse, rel_rmse_8, bias, pixels, note.

    pixels = number of masked pixels. note is None, or says why the metrics are None.
    """
    a, b, mask = _prepare(a, b, mask)
    pixels = int(mask.sum())
    note = None
    if pixels == 0:
        note = "no pixel inside the mask"
    elif not b[mask].mean() > 0:
        note = "reference mean is 0 (or negative): relative errors are undefined"
    return {
        "rel_rmse": rel_rmse(a, b, mask),
        "rel_rmse_8": rel_rmse_8(a, b, mask),
        "bias": bias(a, b, mask),
        "pixels": pixels,
        "note": note,
    }


def hdr_flip(a, b, mask=None) -> float:
    """Mean HDR-FLIP error (NVIDIA flip-evaluator, default viewing conditions) of a vs reference b.

    Negative values are clipped to 0 (FLIP needs non-negative HDR input). With a mask, both images
    are set to 0 outside it (so background differences do not count) and the error map is averaged
    over the masked pixels only.
    """
    try:
        import flip_evaluator
    except ImportError:
        raise BackendUnavailable("HDR-FLIP needs the flip-evaluator package (pip install flip-evaluator)") \
            from None
    a, b, mask = _prepare(a, b, mask)
    if a.shape[2] == 1:
        a, b = np.repeat(a, 3, axis=2), np.repeat(b, 3, axis=2)
    keep = mask[:, :, None]
    a = np.ascontiguousarray(np.where(keep, np.clip(a, 0, None), 0), dtype=np.float32)
    b = np.ascontiguousarray(np.where(keep, np.clip(b, 0, None), 0), dtype=np.float32)
    err_map, _, _ = flip_evaluator.evaluate(b, a, "HDR", applyMagma=False)
    err_map = np.asarray(err_map).reshape(mask.shape)
    return float(err_map[mask].mean()) if mask.any() else 0.0


def cycles_equivalent_speedup(our_error, our_time_s, curve, error_key: str = "rel_rmse_8") -> dict:
    """How much faster we reach `our_error` than Cycles does, along Cycles' error-vs-time curve.

    curve: Cycles measurements at increasing spp, as (time_s, error) pairs or dicts with "time_s"
    and `error_key` (what reference.cycles_curve returns). Cycles' time for our error is found on
    the first segment where the curve drops to our error, by linear interpolation of log(time)
    against log(error) (Monte Carlo error is a power law in time). Returns a dict:

    - cycles_time_s, speedup = cycles_time_s / our_time_s, and bound:
      "=" inside the curve;
      "<" when Cycles' first (fastest) point is already at least as good: Cycles needs at most that
          point's time, so the true speed-up is at most the returned value;
      ">" when no point of the curve is as good as ours: Cycles needs more than its last point's
          time, so the true speed-up is at least the returned value.
    - extrapolated_speedup: only for ">", an estimate assuming Cycles' error keeps falling as
      1/sqrt(time) from its last point: t = t_last * (e_last / our_error)^2. None otherwise or if
      our_error is 0. A guess, flagged as such; the noise floor of the reference limits it too.
    """
    if not our_time_s or our_time_s <= 0:
        raise ConfigError(f"our time must be > 0 s, got {our_time_s}")
    if our_error is None or our_error < 0:
        raise ConfigError(f"our error must be a number >= 0, got {our_error}")
    pts = [(float(p["time_s"]), float(p[error_key])) if isinstance(p, dict) else (float(p[0]), float(p[1]))
           for p in curve]
    pts.sort()
    if not pts:
        raise ConfigError("the Cycles curve is empty")
    tiny = 1e-300  # errors of exactly 0 would make log() fail; they are only met in synthetic data
    extra = None
    j = next((i for i, (_, e) in enumerate(pts) if e <= our_error), None)
    if j is None:
        t_last, e_last = pts[-1]
        t, bound = t_last, ">"
        if our_error > 0:
            extra = t_last * (e_last / our_error) ** 2 / our_time_s
    elif j == 0:
        t, bound = pts[0][0], ("=" if pts[0][1] == our_error else "<")
    else:
        (t0, e0), (t1, e1) = pts[j - 1], pts[j]
        le0, le1, le = (math.log(max(x, tiny)) for x in (e0, e1, our_error))
        f = (le - le0) / (le1 - le0)  # e0 > our_error >= e1 so le0 > le1 and 0 < f <= 1
        t, bound = math.exp(math.log(t0) + f * (math.log(t1) - math.log(t0))), "="
    return {"cycles_time_s": t, "speedup": t / our_time_s, "bound": bound, "extrapolated_speedup": extra}
