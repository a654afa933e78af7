# SPDX-License-Identifier: GPL-3.0-or-later
"""Texels grouped by the direction of their face normal, so that the gather's texel test runs
only over the groups that can face a light view (pure numpy).

On llvmpipe a compute invocation costs its whole shader even when its `if` is false for every
lane, so texels facing away from a light cost as much as lit ones: half of each texel test was
spent on entries that add nothing. The texel list is therefore stored bin by bin (octahedral
cells of the face normal), each bin with the cone holding its faces' normals, and a dispatch
covers only the bins whose cone reaches the front hemisphere of one of its views. Views are
tested in batches of nearby directions (proximity_order), so the bins they need overlap.
Skipped entries would have added nothing (cos <= 0 for every view), so results are unchanged.
"""
from __future__ import annotations

import numpy as np

OCT_SIDE = 16  # 256 bins: cones of up to ~15 degrees, about 12 entry runs per dispatch
BIN_COUNT = OCT_SIDE * OCT_SIDE
# Margin on the cone test: the shader's cos = dot(n, omega) is float32.
_COS_MARGIN = 1e-5


def octahedral_coords(vectors: np.ndarray) -> np.ndarray:
    """(n, 3) vectors -> (n, 2) octahedral map coordinates in [-1, 1]^2 (zero vectors -> 0)."""
    v = np.asarray(vectors, np.float64)
    norm1 = np.abs(v).sum(axis=1)
    p = v / np.where(norm1 > 0.0, norm1, 1.0)[:, None]
    x, y, z = p[:, 0], p[:, 1], p[:, 2]
    lower = z < 0.0
    fx = np.where(lower, (1.0 - np.abs(y)) * np.where(x >= 0.0, 1.0, -1.0), x)
    fy = np.where(lower, (1.0 - np.abs(x)) * np.where(y >= 0.0, 1.0, -1.0), y)
    return np.stack([fx, fy], axis=1)


def normal_bins(normals: np.ndarray) -> np.ndarray:
    """(F, 3) face normals -> (F,) int32 bin in [0, BIN_COUNT): the octahedral cell."""
    cell = np.clip(((octahedral_coords(normals) + 1.0) * 0.5 * OCT_SIDE).astype(np.int64), 0, OCT_SIDE - 1)
    return (cell[:, 1] * OCT_SIDE + cell[:, 0]).astype(np.int32)


def bin_cones(normals: np.ndarray, bins: np.ndarray, used: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Cones holding the unit normals (F, 3) of the used faces (F,) bool of each bin.

    Returns axis (BIN_COUNT, 3) and threshold (BIN_COUNT,): a light omega can face some normal
    of the bin only if axis . omega > threshold (threshold = -sin(half angle), or -2 for bins
    that are empty or whose cone is wider than a hemisphere... then always tested)."""
    n = np.asarray(normals, np.float64)[used]
    b = np.asarray(bins)[used]
    sums = np.zeros((BIN_COUNT, 3))
    np.add.at(sums, b, n)
    length = np.linalg.norm(sums, axis=1)
    axis = np.divide(sums, length[:, None], out=np.zeros_like(sums), where=length[:, None] > 1e-12)
    cos_half = np.ones(BIN_COUNT)
    np.minimum.at(cos_half, b, np.einsum("ij,ij->i", n, axis[b]))
    threshold = np.where(cos_half > 0.0, -np.sqrt(np.clip(1.0 - cos_half * cos_half, 0.0, 1.0)), -2.0)
    threshold[length <= 1e-12] = -2.0
    return axis, threshold


def bins_facing(axis: np.ndarray, threshold: np.ndarray, omegas: np.ndarray) -> np.ndarray:
    """(BIN_COUNT,) bool: bins holding a normal that some of omegas (k, 3) can face."""
    return ((np.asarray(omegas, np.float64) @ axis.T) > threshold - _COS_MARGIN).any(axis=0)


def proximity_order(directions: np.ndarray) -> np.ndarray:
    """(D,) permutation of (D, 3) directions along the Morton curve of their octahedral
    coordinates: consecutive directions are near each other, so a batch of them faces nearly
    the same normal bins."""
    q = np.clip(((octahedral_coords(directions) + 1.0) * 0.5 * 1024).astype(np.int64), 0, 1023)
    code = np.zeros(len(q), np.int64)
    for bit in range(10):
        code |= ((q[:, 0] >> bit) & 1) << (2 * bit)
        code |= ((q[:, 1] >> bit) & 1) << (2 * bit + 1)
    return np.argsort(code, kind="stable")
