# SPDX-License-Identifier: GPL-3.0-or-later
"""Triangle-soup geometry shared by the bakers and the references (float64 numpy)."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass
class TriangleSoup:
    """Triangles in world space, unshared vertices.

    positions: (F, 3, 3) float64 world-space corners.
    uvs: (F, 3, 2) float64 UV corners in [0, 1] (targets only; None for pure occluders).
    name: label for messages.
    """

    positions: np.ndarray
    uvs: np.ndarray | None = None
    name: str = "mesh"

    def __post_init__(self) -> None:
        self.positions = np.asarray(self.positions, dtype=np.float64).reshape(-1, 3, 3)
        if self.uvs is not None:
            self.uvs = np.asarray(self.uvs, dtype=np.float64).reshape(-1, 3, 2)
            if len(self.uvs) != len(self.positions):
                raise ValueError(f"{self.name}: {len(self.uvs)} UV triangles for {len(self.positions)} triangles")

    @property
    def face_count(self) -> int:
        return len(self.positions)


def face_normals_areas(positions: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Unit face normals (F, 3) and areas (F,) of (F, 3, 3) triangles.

    Degenerate (zero-area) triangles get a zero normal and zero area instead of NaN.
    The winding is counter-clockwise: n = (b - a) x (c - a).
    """
    a, b, c = positions[:, 0], positions[:, 1], positions[:, 2]
    cross = np.cross(b - a, c - a)
    length = np.linalg.norm(cross, axis=1)
    # Relative threshold: an area tiny against the triangle's own edge lengths is noise.
    edge = np.maximum(np.max(np.abs(np.stack([b - a, c - a], 1)), axis=(1, 2)), 1e-300)
    valid = length > 1e-12 * edge * edge
    normals = np.zeros_like(cross)
    normals[valid] = cross[valid] / length[valid, None]
    return normals, np.where(valid, 0.5 * length, 0.0)


def uv_areas(uvs: np.ndarray) -> np.ndarray:
    """Unsigned UV-space areas (F,) of (F, 3, 2) UV triangles (in units of the unit square)."""
    d1 = uvs[:, 1] - uvs[:, 0]
    d2 = uvs[:, 2] - uvs[:, 0]
    return 0.5 * np.abs(d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0])


def bounding_sphere(points: np.ndarray) -> tuple[np.ndarray, float]:
    """Centre (3,) and radius of a sphere enclosing points (n, 3): the box centre and
    the farthest point from it (within sqrt(3) of optimal, always enclosing)."""
    pts = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    lo, hi = pts.min(axis=0), pts.max(axis=0)
    centre = 0.5 * (lo + hi)
    radius = float(np.sqrt(((pts - centre) ** 2).sum(axis=1).max()))
    return centre, radius



def is_closed_surface(positions: np.ndarray) -> bool:
    """True when (F, 3, 3) triangles form closed, consistently oriented surfaces: after
    welding bit-identical corner positions, every directed edge a->b occurs exactly once and
    its reverse b->a exactly once (no border, no fin, no flipped face).

    Why it matters: seen from outside, the first surface a ray meets on a closed surface is
    always an entry, i.e. faces the viewer, so a depth map of the front faces alone equals the
    depth map of all faces, and back faces need not be drawn (about 40 % of a light view's
    rasterization cost on llvmpipe). Separate closed objects, touching or intersecting, keep
    the property.
    """
    corners = np.ascontiguousarray(np.asarray(positions, dtype=np.float64).reshape(-1, 3))
    if len(corners) == 0:
        return False
    keys = corners.view(np.dtype((np.void, corners.dtype.itemsize * 3))).ravel()
    _, vertex = np.unique(keys, return_inverse=True)
    tri = vertex.reshape(-1, 3).astype(np.int64)
    a = tri.ravel()
    b = np.roll(tri, -1, axis=1).ravel()
    if (a == b).any():  # a collapsed edge has no partner
        return False
    n = int(vertex.max()) + 1
    forward = np.sort(a * n + b)
    if (np.diff(forward) == 0).any():  # a directed edge used twice: fin or flipped neighbour
        return False
    return bool(np.array_equal(forward, np.sort(b * n + a)))


def boundary_edge_fraction(positions: np.ndarray) -> float:
    """Fraction of the (welded, undirected) edges of (F, 3, 3) triangles that belong to one
    face only: 0 for a closed surface, small for a scan with a few holes, large for sheets."""
    corners = np.ascontiguousarray(np.asarray(positions, dtype=np.float64).reshape(-1, 3))
    if len(corners) == 0:
        return 1.0
    keys = corners.view(np.dtype((np.void, corners.dtype.itemsize * 3))).ravel()
    _, vertex = np.unique(keys, return_inverse=True)
    tri = vertex.reshape(-1, 3).astype(np.int64)
    a, b = tri.ravel(), np.roll(tri, -1, axis=1).ravel()
    n = int(vertex.max()) + 1
    _, counts = np.unique(np.minimum(a, b) * n + np.maximum(a, b), return_counts=True)
    return float((counts == 1).sum() / len(counts))
