# SPDX-License-Identifier: GPL-3.0-or-later
"""What the viewport AO passes draw: world-space triangles per object with a change key
(pure numpy; filled from Blender by hao_addon/blender/view_scene.py or from soups in tests)."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .geometry import TriangleSoup, boundary_edge_fraction, face_normals_areas

# Objects with at most this fraction of border edges are voxelized as solids (a scan with a
# few holes, like the Stanford bunny's open base, at 0.2 %); sheets and planes stay surfaces.
SOLID_BORDER_FRACTION = 0.01


@dataclass
class SceneObject:
    """positions, normals: (F, 3, 3) float32 world corners and corner normals.
    key: anything hashable that changes whenever the geometry or transform does.
    receiver: 1.0 gets AO; 0.5 has a baked AO map (skipped by HAO, still occludes).
    solid: also voxelized by parity (closed or nearly closed).
    proxied: has sphere proxies (left out of the voxels when they stand in for it)."""
    name: str
    key: object
    positions: np.ndarray
    normals: np.ndarray
    receiver: float = 1.0
    solid: bool = False
    proxied: bool = False


def object_from_soup(soup: TriangleSoup, key: object = 0, receiver: float = 1.0) -> SceneObject:
    """Flat-shaded SceneObject of a soup (face normals at every corner)."""
    normals, _ = face_normals_areas(soup.positions)
    return SceneObject(soup.name, key, soup.positions.astype(np.float32),
                       np.repeat(normals[:, None], 3, axis=1).astype(np.float32), receiver,
                       boundary_edge_fraction(soup.positions) <= SOLID_BORDER_FRACTION)


def scene_bounds(objects: list[SceneObject]) -> tuple[np.ndarray, np.ndarray] | None:
    """World box (lo, hi) of all triangles, None when there are none."""
    parts = [o.positions.reshape(-1, 3) for o in objects if len(o.positions)]
    if not parts:
        return None
    return (np.min([p.min(0) for p in parts], axis=0).astype(np.float64),
            np.max([p.max(0) for p in parts], axis=0).astype(np.float64))
