# SPDX-License-Identifier: GPL-3.0-or-later
"""Faces grouped into small, spatially compact chunks, and the chunks a light view must draw
in full because the light looks into a hole there (pure numpy).

A light-view depth map of surfaces that bound solids needs only the faces turned towards the
light, except inside the outline of a hole (core/geometry.surface_holes). Drawing the faces
in Morton order makes every run of CHUNK_FACES faces compact, so a handful of box tests per
view finds the few runs whose averted faces can be seen through a hole; the rest of the
averted faces (on the bunny, most of them) are never drawn.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..geometry import column_bounds

# Faces per chunk, the unit a draw range is cut to: small, because every averted face in a
# picked chunk is drawn (16 draws a third of the faces 128 did on the bunny). The box test
# runs on groups of CHUNKS_PER_GROUP chunks first and on the chunks of the groups it picked,
# so the numpy cost per view stays that of the coarse test.
CHUNK_FACES = 16
CHUNKS_PER_GROUP = 8
_MORTON_BITS = 10


@dataclass
class FaceChunks:
    """order: (F,) int64 face permutation, the draw order; chunk c holds the drawn faces
    c * CHUNK_FACES .. (c + 1) * CHUNK_FACES - 1, group g the chunks g * CHUNKS_PER_GROUP ..
    (g + 1) * CHUNKS_PER_GROUP - 1. boxes: (C, 2, 3) float64 lo and hi corners of each
    chunk's faces; group_boxes: (G, 2, 3) the same of each group's."""

    order: np.ndarray
    boxes: np.ndarray
    group_boxes: np.ndarray


def _spread_bits(v: np.ndarray) -> np.ndarray:
    """Insert two zero bits after each of the low 10 bits of v (uint64)."""
    v = v & np.uint64(0x3FF)
    v = (v | (v << np.uint64(16))) & np.uint64(0x030000FF)
    v = (v | (v << np.uint64(8))) & np.uint64(0x0300F00F)
    v = (v | (v << np.uint64(4))) & np.uint64(0x030C30C3)
    v = (v | (v << np.uint64(2))) & np.uint64(0x09249249)
    return v


def morton_codes(points: np.ndarray) -> np.ndarray:
    """(n,) uint64 Morton codes of points (n, 3) on a 2^10 grid over their box: sorted by
    them, every run of points is compact."""
    lo, hi = column_bounds(points)
    cells = (1 << _MORTON_BITS) - 1
    q = np.clip((points - lo) / np.maximum(hi - lo, 1e-300) * cells, 0, cells).astype(np.uint64)
    return _spread_bits(q[:, 0]) | (_spread_bits(q[:, 1]) << np.uint64(1)) | (_spread_bits(q[:, 2]) << np.uint64(2))


def face_chunks(positions: np.ndarray) -> FaceChunks:
    """Chunks of (F, 3, 3) triangles along the Morton curve of their centroids."""
    tri = np.asarray(positions, dtype=np.float64).reshape(-1, 3, 3)
    count = len(tri)
    if count == 0:
        return FaceChunks(np.zeros(0, np.int64), np.zeros((0, 2, 3)), np.zeros((0, 2, 3)))
    # Per-corner elementwise ops: numpy reductions over an axis of length 3 are ~10x slower.
    centroid = (tri[:, 0] + tri[:, 1] + tri[:, 2]) / 3.0
    order = np.argsort(morton_codes(centroid), kind="stable")
    ordered = tri[order]
    starts = np.arange(0, count, CHUNK_FACES)
    face_lo = np.minimum(np.minimum(ordered[:, 0], ordered[:, 1]), ordered[:, 2])
    face_hi = np.maximum(np.maximum(ordered[:, 0], ordered[:, 1]), ordered[:, 2])
    boxes = np.stack([np.minimum.reduceat(face_lo, starts), np.maximum.reduceat(face_hi, starts)], axis=1)
    groups = np.arange(0, len(boxes), CHUNKS_PER_GROUP)
    group_boxes = np.stack([np.minimum.reduceat(boxes[:, 0], groups),
                            np.maximum.reduceat(boxes[:, 1], groups)], axis=1)
    return FaceChunks(order, boxes, group_boxes)


def _clip_rects(centres: np.ndarray, halves: np.ndarray, linear: np.ndarray,
                offset: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(..., 3) world box centres and half extents -> (..., 3) lo, hi of their clip-space x,
    y, z under orthographic views with (..., 3, 3) linear parts and (..., 3) offsets (z grows
    away from the light). The image of a box's centre plus |linear| times its half extent
    bounds the images of all 8 corners; the relative 1e-9 pad keeps that bound conservative
    under rounding."""
    centre = np.einsum("...ij,...j->...i", linear, centres) + offset
    half = np.einsum("...ij,...j->...i", np.abs(linear), halves)
    half += 1e-9 * (half + np.abs(centre))
    return centre - half, centre + half


def _meets(lo: np.ndarray, hi: np.ndarray, hole_lo: np.ndarray, hole_hi: np.ndarray) -> np.ndarray:
    """(..., 3) clip-space boxes against (..., H, 3) hole boxes -> (...,) bool: the rectangles
    overlap for some hole, and the box reaches farther from the light than that hole's
    nearest point."""
    meets = hi[..., None, 2] >= hole_lo[..., 2]
    for axis in (0, 1):
        meets &= (lo[..., None, axis] <= hole_hi[..., axis]) & (hole_lo[..., axis] <= hi[..., None, axis])
    return meets.any(axis=-1)


def hole_chunk_ranges(chunks: FaceChunks, holes: list[np.ndarray], matrix: np.ndarray,
                      face_count: int) -> list[tuple[int, int]]:
    """(first face, face count) runs, in draw order, covering the chunks whose light-view rectangle
    overlaps the rectangle of some hole's loop under `matrix` (4, 4) orthographic, and that
    reach farther from the light than the loop's nearest point. A ray that enters a capped
    solid through a hole does so inside the loop's convex hull, so faces outside these chunks
    can never be the first surface such a ray meets."""
    return hole_chunk_ranges_many(chunks, holes, np.asarray(matrix)[None], face_count)[0]


def hole_chunk_ranges_many(chunks: FaceChunks, holes: list[np.ndarray], matrices: np.ndarray,
                           face_count: int) -> list[list[tuple[int, int]]]:
    """hole_chunk_ranges for (k, 4, 4) views at once (numpy's per-call overhead, not the
    arithmetic, set the cost of one view: 0.7 ms on the bunny)."""
    views = len(matrices)
    if not holes or len(chunks.boxes) == 0:
        return [[] for _ in range(views)]
    linear = np.asarray(matrices, np.float64)[:, :3, :3]  # (k, 3, 3)
    offset = np.asarray(matrices, np.float64)[:, :3, 3]  # (k, 3)
    # Loops -> clip space in one product; each hole's box per view.
    sizes = [len(h) for h in holes]
    loop_points = np.concatenate(holes).astype(np.float64)
    clip = np.einsum("kij,pj->kpi", linear, loop_points) + offset[:, None]  # (k, P, 3)
    starts = np.cumsum([0] + sizes[:-1])
    hole_lo = np.minimum.reduceat(clip, starts, axis=1)  # (k, H, 3)
    hole_hi = np.maximum.reduceat(clip, starts, axis=1)
    # A group's box holds its chunks' boxes: chunks of groups that miss every hole miss too.
    g_centre = (chunks.group_boxes[:, 0] + chunks.group_boxes[:, 1]) * 0.5
    g_half = (chunks.group_boxes[:, 1] - chunks.group_boxes[:, 0]) * 0.5
    g_lo, g_hi = _clip_rects(g_centre[None], g_half[None], linear[:, None], offset[:, None])  # (k, G, 3)
    view_of, group = np.nonzero(_meets(g_lo, g_hi, hole_lo[:, None], hole_hi[:, None]))
    # (view, chunk) pairs of the picked groups, in view then chunk order.
    chunk = (group[:, None] * CHUNKS_PER_GROUP + np.arange(CHUNKS_PER_GROUP)).ravel()
    view_of = np.repeat(view_of, CHUNKS_PER_GROUP)
    keep = chunk < len(chunks.boxes)
    chunk, view_of = chunk[keep], view_of[keep]
    boxes = chunks.boxes[chunk]
    lo, hi = _clip_rects((boxes[:, 0] + boxes[:, 1]) * 0.5, (boxes[:, 1] - boxes[:, 0]) * 0.5,
                         linear[view_of], offset[view_of])
    picked = _meets(lo, hi, hole_lo[view_of], hole_hi[view_of])
    chunk, view_of = chunk[picked], view_of[picked]
    bounds = np.searchsorted(view_of, np.arange(views + 1))
    return [_runs(chunk[bounds[v]:bounds[v + 1]], face_count) for v in range(views)]


def _runs(picked: np.ndarray, face_count: int) -> list[tuple[int, int]]:
    """(first face, face count) draw runs of ascending picked chunk numbers."""
    if len(picked) == 0:
        return []
    # One run (one draw call) per stretch of picked chunks, bridging gaps of one chunk: on
    # llvmpipe a draw call costs about what 16 faces do, and extra faces never change the map.
    breaks = np.flatnonzero(np.diff(picked) > 2)
    first = np.concatenate([picked[:1], picked[breaks + 1]])
    last = np.concatenate([picked[breaks], picked[-1:]])
    return [(int(a) * CHUNK_FACES, int(min((b + 1) * CHUNK_FACES, face_count) - a * CHUNK_FACES))
            for a, b in zip(first, last)]


def window_chunk_ranges_many(chunks: FaceChunks, matrices: np.ndarray, sizes: np.ndarray,
                             windows: np.ndarray, face_count: int) -> list[list[tuple[int, int]]]:
    """(first face, face count) runs, in draw order, of the chunks whose light-view rectangle
    meets a pixel window, for (k, 4, 4) orthographic views of (k, 2) width, height pixels and
    (k, 4) windows (x, y, width, height) in those pixels. A depth map drawn scissored to its
    window gets nothing from faces outside it, and the nearest depth at a pixel does not
    depend on the order its faces are drawn in: the map is the same, pixel for pixel, as from
    every face (a run of some cells, views cropped from whole ones: views.fit_views)."""
    meets = boxes_meeting_windows(chunks.boxes, matrices, sizes, windows)
    return [_runs(np.flatnonzero(row), face_count) for row in meets]


def boxes_meeting_windows(boxes: np.ndarray, matrices: np.ndarray, sizes: np.ndarray,
                          windows: np.ndarray) -> np.ndarray:
    """(k, C) bool: which of (C, 2, 3) world boxes (lo, hi corners) have a light-view rectangle
    that meets each of k windows (window_chunk_ranges_many's arguments), with a pixel to spare
    on each side: a point in a box that misses that covers no pixel centre inside, and reads
    no pixel inside, whatever the rasterizer rounds."""
    matrices = np.asarray(matrices, np.float64)
    sizes, windows = np.asarray(sizes, np.float64), np.asarray(windows, np.float64)
    if len(boxes) == 0:
        return np.zeros((len(matrices), 0), bool)
    lo_xy = 2.0 * (windows[:, :2] - 1.0) / sizes - 1.0
    hi_xy = 2.0 * (windows[:, :2] + windows[:, 2:] + 1.0) / sizes - 1.0
    centre, half = (boxes[:, 0] + boxes[:, 1]) * 0.5, (boxes[:, 1] - boxes[:, 0]) * 0.5
    # _clip_rects' bound in x, y alone, as matrix products (its einsum cost 0.3 s a re-bake).
    linear = matrices[:, :2, :3].transpose(0, 2, 1)  # (k, 3, 2)
    mid = centre @ linear + matrices[:, None, :2, 3]  # (k, C, 2)
    reach = half @ np.abs(linear)
    reach += 1e-9 * (reach + np.abs(mid))
    return ((mid - reach <= hi_xy[:, None]) & (lo_xy[:, None] <= mid + reach)).all(axis=-1)
