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

CHUNK_FACES = 128
_MORTON_BITS = 10
# Which of a box's 8 corners takes the hi coordinate on each axis.
_CORNER_SELECT = np.array([[(k >> axis) & 1 for axis in range(3)] for k in range(8)], bool)


@dataclass
class FaceChunks:
    """order: (F,) int64 face permutation, the draw order; chunk c holds the drawn faces
    c * CHUNK_FACES .. (c + 1) * CHUNK_FACES - 1. boxes: (C, 2, 3) float64 lo and hi corners."""

    order: np.ndarray
    boxes: np.ndarray


def _spread_bits(v: np.ndarray) -> np.ndarray:
    """Insert two zero bits after each of the low 10 bits of v (uint64)."""
    v = v & np.uint64(0x3FF)
    v = (v | (v << np.uint64(16))) & np.uint64(0x030000FF)
    v = (v | (v << np.uint64(8))) & np.uint64(0x0300F00F)
    v = (v | (v << np.uint64(4))) & np.uint64(0x030C30C3)
    v = (v | (v << np.uint64(2))) & np.uint64(0x09249249)
    return v


def face_chunks(positions: np.ndarray) -> FaceChunks:
    """Chunks of (F, 3, 3) triangles along the Morton curve of their centroids."""
    tri = np.asarray(positions, dtype=np.float64).reshape(-1, 3, 3)
    count = len(tri)
    if count == 0:
        return FaceChunks(np.zeros(0, np.int64), np.zeros((0, 2, 3)))
    centroid = tri.mean(axis=1)
    lo, hi = centroid.min(axis=0), centroid.max(axis=0)
    cells = (1 << _MORTON_BITS) - 1
    q = np.clip((centroid - lo) / np.maximum(hi - lo, 1e-300) * cells, 0, cells).astype(np.uint64)
    code = _spread_bits(q[:, 0]) | (_spread_bits(q[:, 1]) << np.uint64(1)) | (_spread_bits(q[:, 2]) << np.uint64(2))
    order = np.argsort(code, kind="stable")
    starts = np.arange(0, count, CHUNK_FACES)
    ordered = tri[order]
    boxes = np.stack([np.minimum.reduceat(ordered.min(axis=1), starts),
                      np.maximum.reduceat(ordered.max(axis=1), starts)], axis=1)
    return FaceChunks(order, boxes)


def _clip_boxes(points: np.ndarray, matrix: np.ndarray) -> np.ndarray:
    """(..., k, 3) points -> (..., 2, 3) lo/hi of their clip-space x, y, z under an
    orthographic (4, 4) matrix (w = 1; z grows away from the light)."""
    xyz = points @ matrix[:3, :3].T.astype(np.float64) + matrix[:3, 3].astype(np.float64)
    return np.stack([xyz.min(axis=-2), xyz.max(axis=-2)], axis=-2)


def hole_chunk_ranges(chunks: FaceChunks, holes: list[np.ndarray], matrix: np.ndarray,
                      face_count: int) -> list[tuple[int, int]]:
    """(first face, face count) runs, in draw order, of the chunks whose light-view rectangle
    overlaps the rectangle of some hole's loop under `matrix` (4, 4) orthographic, and that
    reach farther from the light than the loop's nearest point. A ray that enters a capped
    solid through a hole does so inside the loop's convex hull, so faces outside these chunks
    can never be the first surface such a ray meets."""
    if not holes or len(chunks.boxes) == 0:
        return []
    lo, hi = chunks.boxes[:, 0], chunks.boxes[:, 1]
    corners = np.where(_CORNER_SELECT[None], hi[:, None, :], lo[:, None, :])  # (C, 8, 3)
    chunk_box = _clip_boxes(corners, matrix)  # (C, 2, 3)
    hole_box = np.stack([_clip_boxes(np.asarray(h, np.float64), matrix) for h in holes])  # (H, 2, 3)
    # Overlapping rectangles in x, y; and the chunk reaches beyond the nearest loop point in
    # z (what a ray meets after entering through the cap lies past the cap).
    c_lo, c_hi = chunk_box[:, None, 0, :], chunk_box[:, None, 1, :]
    h_lo, h_hi = hole_box[None, :, 0, :], hole_box[None, :, 1, :]
    overlap = ((c_lo[..., :2] <= h_hi[..., :2]) & (h_lo[..., :2] <= c_hi[..., :2])).all(axis=2)
    overlap &= c_hi[..., 2] >= h_lo[..., 2]
    overlap = overlap.any(axis=1)
    picked = np.flatnonzero(overlap)
    if len(picked) == 0:
        return []
    # Merge neighbouring chunks into one run (one draw call each).
    breaks = np.flatnonzero(np.diff(picked) > 1)
    first = np.concatenate([picked[:1], picked[breaks + 1]])
    last = np.concatenate([picked[breaks], picked[-1:]])
    return [(int(a) * CHUNK_FACES, int(min((b + 1) * CHUNK_FACES, face_count) - a * CHUNK_FACES))
            for a, b in zip(first, last)]
