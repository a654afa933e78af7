# SPDX-License-Identifier: GPL-3.0-or-later
"""Nested voxel grids (cascades) of viewport HAO: resolution where the view looks (pure numpy).

One grid over the whole region of interest starves what the camera looks at when the region
is large (a character on a wide floor gets a few voxels). So the region's grid is the
coarsest cascade, and each finer cascade has half the voxel size and covers the same number of
voxels around the view's focus (the median visible point near the screen's centre), snapped
to a lattice of its parent's voxels so that small camera moves leave it where it is (and
unvoxelized again). A cascade is added while it still covers the focus area (twice the
frustum's half-width there): a finer grid that covers only part of what is on screen would
split it, except where d_max spans only a few voxels (MIN_REACH_VOXELS): there resolution
decides the error, and the points the finer grid covers gain it. A ray starts in the finest
cascade holding its point and continues in the next coarser one where it leaves a cascade's
box (hao_march.glsl).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .voxel_grid import GridSpec, grid_for_bounds

MAX_CASCADES = 6
# A cascade's origin moves in steps of this many of its parent's voxels.
SNAP_VOXELS = 8
# A finer cascade is added while its box spans this many focus radii along every axis (or
# all of its parent along it).
FOCUS_COVER = 2.0
# Finer cascades are also added, covering what they can around the focus, while d_max spans
# fewer than this many voxels of the finest one: the march places a hit up to a voxel late
# (centre, not entry) and ignores its receiver's one-voxel slab, errors the falloff weighs by
# their share of d_max. Measured (hao_bench's multi-object scene and bunny at d_max 0.05 x
# their height, 3.3 voxels of one grid): RMSE 0.036 / 0.014 with one grid, 0.030 / 0.009 with
# d_max at 6.5 voxels, 0.030 / 0.007 at 13 and no better at 26.
MIN_REACH_VOXELS = 8.0


@dataclass(frozen=True)
class Focus:
    """Where the view looks: a point (anchor-relative world) and the half-width of the view
    frustum there (world units)."""
    point: tuple[float, float, float]
    radius: float


def cascade_specs(lo: np.ndarray, hi: np.ndarray, resolution: int, count: int,
                  focus: Focus | None, max_distance: float = 0.0) -> tuple[GridSpec, ...]:
    """The cascades' grids, finest first, the last one grid_for_bounds(lo, hi, resolution).
    count: at most this many; fewer where a finer one would not cover the focus area (unless
    max_distance > 0 spans fewer than MIN_REACH_VOXELS of the finest so far), and one
    without a focus."""
    outer = grid_for_bounds(lo, hi, resolution)
    specs = [outer]
    if focus is None or not np.all(np.isfinite(focus.point)) or not focus.radius > 0.0:
        return tuple(specs)
    point = np.asarray(focus.point, np.float64)
    while len(specs) < min(count, MAX_CASCADES):
        parent = specs[-1]
        child = _child(parent, resolution, point)
        extent = np.asarray(child.dims) * child.voxel
        needed = np.minimum(FOCUS_COVER * focus.radius, np.asarray(parent.dims) * parent.voxel)
        short_reach = 0.0 < max_distance < MIN_REACH_VOXELS * parent.voxel
        if np.any(extent < needed * (1.0 - 1e-9)) and not short_reach:
            break
        specs.append(child)
    return tuple(reversed(specs))


def _child(parent: GridSpec, resolution: int, point: np.ndarray) -> GridSpec:
    """Half the parent's voxel, `resolution` voxels per axis (nz a multiple of 32) but not
    more than the parent spans, centred on the point, snapped to SNAP_VOXELS parent voxels
    and kept inside the parent's box."""
    voxel = parent.voxel / 2.0
    span = np.asarray(parent.dims) * 2
    dims = np.minimum(np.full(3, resolution), span)
    dims[2] = -(-dims[2] // 32) * 32
    p_origin = np.asarray(parent.origin)
    step = SNAP_VOXELS * parent.voxel
    origin = p_origin + np.round((point - 0.5 * dims * voxel - p_origin) / step) * step
    hi_limit = p_origin + np.asarray(parent.dims) * parent.voxel - dims * voxel
    origin = np.clip(origin, p_origin, np.maximum(hi_limit, p_origin))
    return GridSpec(tuple(float(x) for x in origin), float(voxel), tuple(int(x) for x in dims))


def contains(spec: GridSpec, point: np.ndarray) -> bool:
    g = spec.to_grid(point)
    return bool(np.all(g >= 0.0) and np.all(g < np.asarray(spec.dims)))


def focus_from_depth(depth: np.ndarray, inverse_view_proj: np.ndarray, size: tuple[int, int]) -> Focus | None:
    """The focus from a depth image: the median depth of the covered pixels in the central
    half of the screen, unprojected at the screen's centre, and the frustum's half-width
    there (the larger of the horizontal and vertical). depth: (h, w) window depths of the
    central region (1 = background); inverse_view_proj: (4, 4) clip -> world; size: the
    whole image's (width, height). None where nothing covers the centre."""
    covered = depth[depth < 1.0]
    if covered.size == 0:
        return None
    z = float(np.median(covered)) * 2.0 - 1.0

    def unproject(x: float, y: float) -> np.ndarray:
        p = inverse_view_proj @ np.array([x, y, z, 1.0])
        return p[:3] / p[3]

    centre = unproject(0.0, 0.0)
    radius = max(np.linalg.norm(unproject(1.0, 0.0) - centre), np.linalg.norm(unproject(0.0, 1.0) - centre))
    if not np.all(np.isfinite(centre)) or not np.isfinite(radius):
        return None
    return Focus(tuple(float(x) for x in centre), float(radius))


def atlas_layout(specs: tuple[GridSpec, ...]) -> tuple[tuple[int, int, int], list[int]]:
    """One R32UI 3D texture holds every cascade's pyramid atlas (voxel_grid.atlas_words),
    stacked along y: (texture size (x, y, z words), each cascade's y offset)."""
    from .voxel_grid import atlas_words
    words = [atlas_words(s.dims) for s in specs]
    offsets = [int(sum(w[1] for w in words[:k])) for k in range(len(words))]
    size = (max(w[0] for w in words), int(sum(w[1] for w in words)), max(w[2] for w in words))
    return size, offsets
