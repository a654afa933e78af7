# SPDX-License-Identifier: GPL-3.0-or-later
"""Blocks of a texel list's entries for views cropped to a window (pure numpy).

A re-bake by difference (hao_addon/rebake_difference.py) crops every light view to the few
pixels an edit can change; an entry whose point projects elsewhere reads lit in both of its
bakes and adds nothing to their difference. Kept in Morton order within each normal bin, the
entries form compact blocks of BLOCK_ENTRIES: a box test per block and view finds the few
blocks a window can reach, and only their entries are dispatched.
"""
from __future__ import annotations

import numpy as np

from .face_chunks import morton_codes

BLOCK_ENTRIES = 128
BRIDGED_BLOCKS = 8


def block_order(points: np.ndarray, bins: np.ndarray, cells: np.ndarray) -> np.ndarray:
    """(n,) the permutation of entries at points (n, 3) in cells (n,) that keeps their bins
    (n,) in order (ascending) and puts each bin's entries in Morton order, ties by cell and
    point: the same entries, listed in any order (a GPU's atomic counters), come out in the
    same order (the two bakes of a difference match entry by entry)."""
    morton = morton_codes(points)
    if len(cells) and int(cells.max()) < 1 << 24 and int(bins.max()) < 1 << 10:
        # One 64-bit key (bin, code, cell): an argsort, 5x faster than lexsort; unique where
        # each cell has one entry (overlapping UVs may give one two: lexsort then).
        key = (bins.astype(np.uint64) << np.uint64(54)) | (morton << np.uint64(24)) | cells.astype(np.uint64)
        order = np.argsort(key, kind="stable")
        if not (np.diff(key[order]) == 0).any():
            return order
    return np.lexsort((points[:, 2], points[:, 1], points[:, 0], cells, morton, bins))


def block_boxes(lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """(B, 2, 3) the box of each block of BLOCK_ENTRIES consecutive entries spanning lo..hi
    (n, 3) each (an entry's point, or the segment to its lifted end)."""
    starts = np.arange(0, len(lo), BLOCK_ENTRIES)
    if len(starts) == 0:
        return np.zeros((0, 2, 3))
    return np.stack([np.minimum.reduceat(lo, starts), np.maximum.reduceat(hi, starts)], axis=1)


def block_runs(needed: np.ndarray, count: int) -> list[tuple[int, int]]:
    """(first, end) entry runs of the needed blocks (B,) bool of a list of `count` entries."""
    picked = np.flatnonzero(needed)
    if len(picked) == 0:
        return []
    # Gaps of up to BRIDGED_BLOCKS join their neighbours: a dispatch costs llvmpipe about what
    # testing a few blocks does, and an entry outside a window adds nothing to a difference.
    breaks = np.flatnonzero(np.diff(picked) > BRIDGED_BLOCKS + 1)
    first = np.concatenate([picked[:1], picked[breaks + 1]])
    last = np.concatenate([picked[breaks], picked[-1:]])
    return [(int(a) * BLOCK_ENTRIES, int(min((b + 1) * BLOCK_ENTRIES, count))) for a, b in zip(first, last)]


def intersected_runs(a: list[tuple[int, int]], b: list[tuple[int, int]]) -> list[tuple[int, int]]:
    """The (first, end) runs covered by both ascending, disjoint run lists a and b."""
    out, i, j = [], 0, 0
    while i < len(a) and j < len(b):
        first, end = max(a[i][0], b[j][0]), min(a[i][1], b[j][1])
        if first < end:
            out.append((first, end))
        if a[i][1] < b[j][1]:
            i += 1
        else:
            j += 1
    return out
