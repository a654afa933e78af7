# SPDX-License-Identifier: GPL-3.0-or-later
"""A uniform grid over triangles, the acceleration structure of the GPU ray cast of the
Selected-to-Active projection (gpu/bake_ray_cast.py walks it with a 3D DDA).

Why a uniform grid and not a BVH: the projection's rays are short (they start a cage
extrusion away from the high-poly and stop at its surface), so a ray visits a few cells of
about a triangle's size; a grid is built by numpy in tens of milliseconds with no per-node
Python, and its traversal has no stack. Each triangle is listed in every cell its bounding
box overlaps (conservative: a ray tests a few triangles it cannot hit, never misses one).
Coordinates are in cell units from the grid's low corner, so float32 keeps the same
relative precision on a mesh of any size or position.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

# About this many cells per triangle (measured on the bunny pair at 601k rays: 2 cells per
# triangle tests ~3 triangles per cell visited).
CELLS_PER_TRIANGLE = 2.0
# At most this many cells along an axis and in all (a flat or very long mesh would otherwise
# ask for millions of thin cells).
MAX_CELLS_PER_AXIS = 512
MAX_CELLS = 1 << 22
# The box is padded by this fraction of its largest extent, so that a mesh lying in a plane
# (zero extent along one axis) still has one layer of cells of positive thickness.
BOX_PADDING = 1e-4


@dataclass
class UniformGrid:
    """lo (3,) float64: the world position of cell (0, 0, 0)'s low corner; cell: the side of a
    cubic cell (world units); dims (3,) int64: cells along x, y, z; cell_start
    (cells + 1,) int64: triangle_index[cell_start[c]:cell_start[c + 1]] are the triangles of
    cell c = (z * dims[1] + y) * dims[0] + x; local_triangles (F, 3, 3) float32: the
    triangles' corners in cell units (world - lo) / cell."""

    lo: np.ndarray
    cell: float
    dims: np.ndarray
    cell_start: np.ndarray
    triangle_index: np.ndarray
    local_triangles: np.ndarray

    @property
    def cell_count(self) -> int:
        return int(np.prod(self.dims))

    def to_local(self, points: np.ndarray) -> np.ndarray:
        """(m, 3) world points in cell units, float64."""
        return (np.asarray(points, np.float64) - self.lo) / self.cell


def grid_shape(lo: np.ndarray, hi: np.ndarray, face_count: int) -> tuple[float, np.ndarray]:
    """(cell side, dims (3,)) of a grid over the box lo..hi with about CELLS_PER_TRIANGLE cells
    per triangle, within MAX_CELLS_PER_AXIS and MAX_CELLS."""
    extent = hi - lo
    wanted = min(max(CELLS_PER_TRIANGLE * face_count, 1.0), float(MAX_CELLS))
    cell = max(float(np.prod(extent) / wanted) ** (1.0 / 3.0), float(extent.max()) / MAX_CELLS_PER_AXIS)
    dims = np.maximum(np.ceil(extent / cell - 1e-9).astype(np.int64), 1)
    while int(np.prod(dims)) > MAX_CELLS:  # rounding up can overshoot by a few per cent
        cell *= 1.01
        dims = np.maximum(np.ceil(extent / cell - 1e-9).astype(np.int64), 1)
    return cell, dims


def build_grid(triangles: np.ndarray) -> UniformGrid:
    """The grid of triangles (F, 3, 3) world (finite, F >= 1)."""
    tri = np.asarray(triangles, np.float64)
    lo, hi = tri.reshape(-1, 3).min(axis=0), tri.reshape(-1, 3).max(axis=0)
    magnitude = float(np.abs(np.concatenate([lo, hi])).max())
    pad = BOX_PADDING * max(float((hi - lo).max()), 1e-6 * magnitude, 1e-30)
    lo, hi = lo - pad, hi + pad
    cell, dims = grid_shape(lo, hi, len(tri))
    local = (tri - lo) / cell
    first = np.clip(np.floor(local.min(axis=1)).astype(np.int64), 0, dims - 1)  # (F, 3) cell ranges
    last = np.clip(np.floor(local.max(axis=1)).astype(np.int64), 0, dims - 1)
    span = last - first + 1
    counts = span.prod(axis=1)
    owner = np.repeat(np.arange(len(tri)), counts)
    # The k-th cell of a triangle's box, as (dx, dy, dz) within it.
    k = np.arange(int(counts.sum())) - np.repeat(np.cumsum(counts) - counts, counts)
    sx, sy = span[owner, 0], span[owner, 1]
    dx, dy, dz = k % sx, (k // sx) % sy, k // (sx * sy)
    x, y, z = first[owner, 0] + dx, first[owner, 1] + dy, first[owner, 2] + dz
    cell_id = (z * dims[1] + y) * dims[0] + x
    order = np.argsort(cell_id, kind="stable")
    cell_start = np.concatenate([[0], np.cumsum(np.bincount(cell_id, minlength=int(np.prod(dims))))])
    return UniformGrid(lo, cell, dims, cell_start.astype(np.int64), owner[order].astype(np.int64),
                       local.astype(np.float32))
