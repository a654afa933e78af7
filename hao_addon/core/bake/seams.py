# SPDX-License-Identifier: GPL-3.0-or-later
"""Seam repair and margin (McGraw & Sowers section 3.3), on the normalized AO map.

Erosion drops texels whose UV coverage is too small to trust (on a chart's rim a texel holds
only a sliver of surface, so its estimate rests on few samples and on the tent's tail);
dilation then refills them, and grows every chart by `margin` texels, with the mean of the
valid 8-neighbours, ring by ring, as Cycles' "Extend" margin does. The margin keeps bilinear
and mip-mapped lookups from reading the background at chart borders.
"""
from __future__ import annotations

import numpy as np

from ..geometry import unit_vectors

MIN_COVERAGE = 0.5


def estimated(weight: np.ndarray, elements: bool = False) -> np.ndarray:
    """(...) bool: the texels (or, with elements, colour-attribute elements) whose value is the
    bake's own estimate, from their accumulated weight (...): a texel's coverage at least
    MIN_COVERAGE (the others are grown from their neighbours, finalize_map), an element any.
    The map's stated error covers these, and its floor check samples them."""
    return weight > 0.0 if elements else weight >= MIN_COVERAGE
_OFFSETS = [(-1, -1), (-1, 0), (-1, 1), (0, -1), (0, 1), (1, -1), (1, 0), (1, 1)]


def _shift(a: np.ndarray, dy: int, dx: int, fill) -> np.ndarray:
    """a shifted so that out[y, x] = a[y + dy, x + dx] (fill outside)."""
    out = np.full_like(a, fill)
    h, w = a.shape
    ys, yd = (slice(dy, h), slice(0, h - dy)) if dy >= 0 else (slice(0, h + dy), slice(-dy, h))
    xs, xd = (slice(dx, w), slice(0, w - dx)) if dx >= 0 else (slice(0, w + dx), slice(-dx, w))
    out[yd, xd] = a[ys, xs]
    return out


def dilate(values: np.ndarray, valid: np.ndarray, rings: int) -> tuple[np.ndarray, np.ndarray]:
    """Grow the valid region by `rings` texels, each new texel the mean of its valid
    8-neighbours. values: (H, W) float; valid: (H, W) bool. Returns new (values, valid).

    Works on the frontier only (the invalid texels next to valid ones, ring by ring), so the
    cost follows the texels grown, not the map: 1024^2 with 18 rings went from 0.38 s (whole
    shifted images per ring) to a few tens of ms. Sums run in the same neighbour order in
    float32 as whole-image shifts would, so the result does not depend on the method.
    """
    h, w = valid.shape
    pw = w + 2  # one texel of never-valid padding: neighbours never leave the array
    vals = np.zeros((h + 2) * pw, np.float32)
    ok = np.zeros((h + 2) * pw, bool)
    inside = np.zeros((h + 2, pw), bool)
    inside[1:-1, 1:-1] = True
    inside = inside.ravel()
    vals.reshape(h + 2, pw)[1:-1, 1:-1] = np.where(valid, values, 0.0)
    ok.reshape(h + 2, pw)[1:-1, 1:-1] = valid
    offsets = np.array([dy * pw + dx for dy, dx in _OFFSETS], np.intp)
    okg = ok.reshape(h + 2, pw)
    near = np.zeros_like(okg)
    for dy, dx in _OFFSETS:  # first frontier: whole-image shifts, once
        near[1:-1, 1:-1] |= okg[1 + dy:h + 1 + dy, 1 + dx:w + 1 + dx]
    frontier = np.flatnonzero(near.ravel() & ~ok & inside)
    mark = np.zeros_like(ok)
    for _ in range(rings):
        if len(frontier) == 0:
            break
        neighbours = offsets[:, None] + frontier  # (8, n): one contiguous row per offset
        # Texels not valid yet hold 0, so plain sums over all 8 neighbours are the sums over
        # the valid ones, added row by row in the neighbour order of the definition.
        gathered = vals[neighbours]
        total = gathered[0].copy()
        for k in range(1, len(offsets)):
            total += gathered[k]
        count = np.add.reduce(ok[neighbours], axis=0, dtype=np.float32)
        vals[frontier] = total / count
        ok[frontier] = True
        mark[neighbours.ravel()] = True
        frontier = np.flatnonzero(mark & ~ok & inside)
        mark[:] = False
    out_vals = vals.reshape(h + 2, pw)[1:-1, 1:-1]
    out_valid = ok.reshape(h + 2, pw)[1:-1, 1:-1]
    return np.where(out_valid, out_vals, values.astype(np.float32)).astype(np.float32), out_valid.copy()


def grow_mask(mask: np.ndarray, rings: int) -> np.ndarray:
    """Binary 8-neighbour dilation of mask (H, W) bool by `rings` texels."""
    out = mask.copy()
    for _ in range(rings):
        grown = out.copy()
        for dy, dx in _OFFSETS:
            grown |= _shift(out, dy, dx, False)
        out = grown
    return out


def element_values(numerator: np.ndarray, weight: np.ndarray, background: float = 1.0
                   ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A colour attribute's values from its per-element sums (n,) (each lit corner weighs 1):
    (ao (n,) float32 in [0, 1], covered (n,) bool: sampled by a lit corner, filled: the same;
    unsampled elements hold `background`). No margins: elements have no neighbours to bleed."""
    covered = estimated(weight, elements=True)
    ratio = np.divide(numerator, weight, out=np.full_like(numerator, background), where=covered)
    return np.clip(ratio, 0.0, 1.0).astype(np.float32), covered, covered.copy()


def finalize_map(numerator: np.ndarray, coverage: np.ndarray, margin: int,
                 background: float = 1.0) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Accessibility map from the accumulated sums.

    numerator: (H, W) float64 visible weight; coverage: (H, W) float64 total weight (the
    texel's UV coverage, about 1 inside a chart). Returns (ao (H, W) float32 in [0, 1], covered
    (H, W) bool: texels with a trusted estimate, filled (H, W) bool: every texel a UV
    triangle touches plus `margin` rings). Texels outside hold `background`.
    """
    covered = estimated(coverage)
    ratio = np.divide(numerator, coverage, out=np.zeros_like(numerator), where=covered)
    ao = np.clip(ratio, 0.0, 1.0).astype(np.float32)
    # Erosion is the MIN_COVERAGE threshold. Dilation refills the eroded rim (at most two
    # texels wide: the tent reaches one texel past a triangle) and then grows the margin.
    target = grow_mask(coverage > 0.0, margin)
    ao, filled = dilate(ao, covered, margin + 2)
    filled &= target
    ao = np.where(filled, ao, np.float32(background))
    return ao, covered, filled


def finalize_vectors(vectors: np.ndarray, covered: np.ndarray, filled: np.ndarray, margin: int) -> np.ndarray:
    """(H, W, 3) float32 unit vectors (a bent-normal map): vectors (H, W, 3) where covered,
    grown over the rim and margin as finalize_map grows the AO (each component by the same
    neighbours, then renormalized), zero outside filled."""
    grown = np.stack([dilate(vectors[..., c].astype(np.float32), covered, margin + 2)[0] for c in range(3)], -1)
    return np.where(filled[..., None], unit_vectors(grown), np.float32(0.0)).astype(np.float32)
