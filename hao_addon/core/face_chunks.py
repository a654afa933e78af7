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


def face_chunks(positions: np.ndarray) -> FaceChunks:
    """Chunks of (F, 3, 3) triangles along the Morton curve of their centroids."""
    tri = np.asarray(positions, dtype=np.float64).reshape(-1, 3, 3)
    count = len(tri)
    if count == 0:
        return FaceChunks(np.zeros(0, np.int64), np.zeros((0, 2, 3)), np.zeros((0, 2, 3)))
    centroid = tri.mean(axis=1)
    lo, hi = centroid.min(axis=0), centroid.max(axis=0)
    cells = (1 << _MORTON_BITS) - 1
    q = np.clip((centroid - lo) / np.maximum(hi - lo, 1e-300) * cells, 0, cells).astype(np.uint64)
    code = _spread_bits(q[:, 0]) | (_spread_bits(q[:, 1]) << np.uint64(1)) | (_spread_bits(q[:, 2]) << np.uint64(2))
    order = np.argsort(code, kind="stable")
    ordered = tri[order]
    starts = np.arange(0, count, CHUNK_FACES)
    boxes = np.stack([np.minimum.reduceat(ordered.min(axis=1), starts),
                      np.maximum.reduceat(ordered.max(axis=1), starts)], axis=1)
    groups = np.arange(0, len(boxes), CHUNKS_PER_GROUP)
    group_boxes = np.stack([np.minimum.reduceat(boxes[:, 0], groups),
                            np.maximum.reduceat(boxes[:, 1], groups)], axis=1)
    return FaceChunks(order, boxes, group_boxes)


def _clip_rects(boxes: np.ndarray, matrix: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(N, 2, 3) world boxes -> (N, 3) lo, hi of their clip-space x, y, z under an
    orthographic (4, 4) matrix (z grows away from the light). The image of a box's centre
    plus |matrix| times its half extent bounds the images of all 8 corners; the relative
    1e-9 pad keeps that bound conservative under rounding."""
    linear = matrix[:3, :3].astype(np.float64)
    centre = (boxes[:, 0] + boxes[:, 1]) * 0.5 @ linear.T + matrix[:3, 3].astype(np.float64)
    half = (boxes[:, 1] - boxes[:, 0]) * 0.5 @ np.abs(linear).T
    half += 1e-9 * (half + np.abs(centre))
    return centre - half, centre + half


def _behind_a_hole(boxes: np.ndarray, hole_lo: np.ndarray, hole_hi: np.ndarray,
                   matrix: np.ndarray) -> np.ndarray:
    """(N, 2, 3) world boxes -> (N,) bool: the box's light-view rectangle overlaps some hole's
    (hole_lo, hole_hi: (H, 3) clip-space corners) and the box reaches farther from the light
    than that hole's nearest point."""
    lo, hi = _clip_rects(boxes, matrix)
    meets = hi[:, None, 2] >= hole_lo[None, :, 2]
    for axis in (0, 1):
        meets &= (lo[:, None, axis] <= hole_hi[None, :, axis]) & (hole_lo[None, :, axis] <= hi[:, None, axis])
    return meets.any(axis=1)


def hole_chunk_ranges(chunks: FaceChunks, holes: list[np.ndarray], matrix: np.ndarray,
                      face_count: int) -> list[tuple[int, int]]:
    """(first face, face count) runs, in draw order, covering the chunks whose light-view rectangle
    overlaps the rectangle of some hole's loop under `matrix` (4, 4) orthographic, and that
    reach farther from the light than the loop's nearest point. A ray that enters a capped
    solid through a hole does so inside the loop's convex hull, so faces outside these chunks
    can never be the first surface such a ray meets."""
    if not holes or len(chunks.boxes) == 0:
        return []
    # Loops -> clip space in one product; each hole's rectangle and nearest depth.
    sizes = [len(h) for h in holes]
    clip = np.concatenate(holes).astype(np.float64) @ matrix[:3, :3].T.astype(np.float64) + matrix[:3, 3]
    starts = np.cumsum([0] + sizes[:-1])
    hole_lo, hole_hi = np.minimum.reduceat(clip, starts), np.maximum.reduceat(clip, starts)
    # A group's box holds its chunks' boxes: chunks of groups that miss every hole miss too.
    groups = np.flatnonzero(_behind_a_hole(chunks.group_boxes, hole_lo, hole_hi, matrix))
    if len(groups) == 0:
        return []
    candidates = (groups[:, None] * CHUNKS_PER_GROUP + np.arange(CHUNKS_PER_GROUP)).ravel()
    candidates = candidates[candidates < len(chunks.boxes)]
    picked = candidates[_behind_a_hole(chunks.boxes[candidates], hole_lo, hole_hi, matrix)]
    if len(picked) == 0:
        return []
    # One run (one draw call) per stretch of picked chunks, bridging gaps of one chunk: on
    # llvmpipe a draw call costs about what 16 faces do, and extra faces never change the map.
    breaks = np.flatnonzero(np.diff(picked) > 2)
    first = np.concatenate([picked[:1], picked[breaks + 1]])
    last = np.concatenate([picked[breaks], picked[-1:]])
    return [(int(a) * CHUNK_FACES, int(min((b + 1) * CHUNK_FACES, face_count) - a * CHUNK_FACES))
            for a, b in zip(first, last)]
