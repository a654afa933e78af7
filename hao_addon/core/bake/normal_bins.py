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

With shading normals an entry is binned by its own (interpolated) shading normal, the one its
weight is about, and a bin's cone is its octahedral cell's (cell_cones): binned by face normal
with cones holding the faces' corner normals, the cones were 36-41 degrees wide at the median
on the smooth rocker arm and bunny (their facets and corner normals disagree that much), and a
single direction needed 80-85 % of the entries instead of about 55 %.
"""
from __future__ import annotations

import functools
from dataclasses import dataclass

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


def octahedral_decode(coords: np.ndarray) -> np.ndarray:
    """(n, 2) octahedral coordinates -> (n, 3) unit vectors (gpu_shaders/octahedral.glsl's twin)."""
    f = np.asarray(coords, np.float64)
    n = np.stack([f[:, 0], f[:, 1], 1.0 - np.abs(f[:, 0]) - np.abs(f[:, 1])], axis=1)
    t = np.maximum(-n[:, 2], 0.0)
    n[:, 0] += np.where(n[:, 0] >= 0.0, -t, t)
    n[:, 1] += np.where(n[:, 1] >= 0.0, -t, t)
    return n / np.linalg.norm(n, axis=1, keepdims=True)


# A cell's extent is measured on a grid of _CELL_SAMPLES^2 points over it (edges included).
# Lines of the octahedral map are great-circle arcs on each octahedron face, so the farthest
# point from the axis is a corner or where an edge crosses a face border (the equator fold
# |x| + |y| = 1, or an axis); the grid comes within 1/64 of a cell of those, and _CELL_MARGIN
# (in cos) covers that (at most about 8e-4 at the fold's kink; computed once per session).
_CELL_SAMPLES = 33
_CELL_MARGIN = 2e-3


@functools.cache
def cell_cones() -> tuple[np.ndarray, np.ndarray]:
    """The cone (axis (BIN_COUNT, 3), threshold (BIN_COUNT,), as bin_cones returns) of every
    octahedral cell: it holds every unit vector that normal_bins puts in that bin."""
    t = np.linspace(0.0, 1.0, _CELL_SAMPLES)
    grid = np.stack(np.meshgrid(t, t), -1).reshape(-1, 2) * (2.0 / OCT_SIDE)
    cy, cx = np.divmod(np.arange(BIN_COUNT), OCT_SIDE)
    low = np.stack([cx, cy], 1) * (2.0 / OCT_SIDE) - 1.0  # (BIN_COUNT, 2) cell corner
    points = octahedral_decode((low[:, None, :] + grid[None]).reshape(-1, 2)).reshape(BIN_COUNT, -1, 3)
    axis = points.sum(axis=1)
    axis /= np.linalg.norm(axis, axis=1, keepdims=True)
    cos_half = np.einsum("bpd,bd->bp", points, axis).min(axis=1) - _CELL_MARGIN
    threshold = np.where(cos_half > 0.0, -np.sqrt(np.clip(1.0 - cos_half * cos_half, 0.0, 1.0)), -2.0)
    return axis, threshold


def bins_facing(axis: np.ndarray, threshold: np.ndarray, omegas: np.ndarray) -> np.ndarray:
    """(BIN_COUNT,) bool: bins holding a normal that some of omegas (k, 3) can face."""
    return ((np.asarray(omegas, np.float64) @ axis.T) > threshold - _COS_MARGIN).any(axis=0)


def bin_runs(needed: np.ndarray, bin_first: np.ndarray) -> list[tuple[int, int]]:
    """(first, end) item runs of the needed bins (BIN_COUNT,) bool, of a list stored bin by bin
    (bin b holds items bin_first[b] .. bin_first[b + 1] - 1): empty bins join their
    neighbours' runs, so the runs are as few as the needed bins allow."""
    needed = needed | (bin_first[1:] == bin_first[:-1])
    picked = np.flatnonzero(needed)
    if len(picked) == 0:
        return []
    breaks = np.flatnonzero(np.diff(picked) > 1)
    first = np.concatenate([picked[:1], picked[breaks + 1]])
    last = np.concatenate([picked[breaks], picked[-1:]])
    runs = [(int(bin_first[a]), int(bin_first[b + 1])) for a, b in zip(first, last)]
    return [(a, b) for a, b in runs if b > a]


@dataclass
class FaceBins:
    """Faces stored by the normal bin of their face normal, for depth maps that need only the
    faces turned towards (or away from) the light: order (F,) the face permutation, bin_first
    (BIN_COUNT + 1,) each bin's first face in that order, axis and threshold its cone."""

    order: np.ndarray
    bin_first: np.ndarray
    axis: np.ndarray
    threshold: np.ndarray

    @classmethod
    def of(cls, normals: np.ndarray) -> "FaceBins":
        """normals: (F, 3) face normals (zero for degenerate faces, which stay in every run)."""
        bins = normal_bins(normals)
        order = np.argsort(bins, kind="stable")
        bin_first = np.concatenate([[0], np.cumsum(np.bincount(bins, minlength=BIN_COUNT))]).astype(np.int64)
        used = np.abs(np.asarray(normals)).sum(axis=1) > 0.0
        axis, threshold = bin_cones(normals, bins, used)
        threshold[np.bincount(bins[~used], minlength=BIN_COUNT) > 0] = -2.0
        return cls(order, bin_first, axis, threshold)

    def runs(self, omega: np.ndarray) -> list[tuple[int, int]]:
        """(first face, end face) runs of the bins holding a face that omega (3,) can face."""
        return bin_runs(bins_facing(self.axis, self.threshold, np.asarray(omega)[None]), self.bin_first)


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
