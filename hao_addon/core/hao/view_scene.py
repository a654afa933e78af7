# SPDX-License-Identifier: GPL-3.0-or-later
"""What the viewport AO passes draw: world-space triangles per object with a change key
(pure numpy; filled from Blender by hao_addon/blender/view_scene.py or from soups in tests)."""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..geometry import TriangleSoup, boundary_edge_fraction, face_normals_areas

# How the voxelization fills an object's inside (parity along z, core/hao/voxel_grid.py):
# OPEN objects (sheets, planes) stay surfaces; NEARLY_CLOSED ones have at most
# SOLID_BORDER_FRACTION border edges (a scan with a few holes, like the Stanford bunny's open
# base, at 0.2 %); CLOSED ones have none.
OPEN, NEARLY_CLOSED, CLOSED = 0, 1, 2
SOLID_BORDER_FRACTION = 0.01


def fill_class(positions: np.ndarray) -> int:
    """OPEN, NEARLY_CLOSED or CLOSED for (F, 3, 3) triangles."""
    border = boundary_edge_fraction(positions)
    return CLOSED if border == 0.0 else (NEARLY_CLOSED if border <= SOLID_BORDER_FRACTION else OPEN)


def filled_classes(march: str) -> int:
    """The least fill class a march fills. The paper's fixed steps step over shells, so every
    (nearly) closed object is filled; the hierarchical march visits every voxel and needs a
    fill only where a surface lies inside its slab (an occluder resting on the receiver:
    under a ball on a floor the ray passes the ball's lower shell there and would next meet
    its far side), and only closed objects are filled, since a scan's holes would leak the
    fill (below the bunny's open base: its whole column)."""
    return NEARLY_CLOSED if march == "fixed" else CLOSED


@dataclass
class SceneObject:
    """positions, normals: (F, 3, 3) float32 corners relative to `offset` (float64 world, the
    object's box centre, so that float32 keeps its precision far from the origin) and
    world corner normals.
    key: anything hashable that changes whenever the geometry or transform does.
    receiver: 1.0 gets AO; 0.5 has a baked AO map (skipped by HAO, still occludes).
    fill: OPEN, NEARLY_CLOSED or CLOSED (fill_class): which marches fill its inside."""
    name: str
    key: object
    positions: np.ndarray
    normals: np.ndarray
    receiver: float = 1.0
    fill: int = OPEN
    offset: np.ndarray = field(default_factory=lambda: np.zeros(3))

    def world_positions(self) -> np.ndarray:
        """(F, 3, 3) float64 world corners."""
        return self.positions.astype(np.float64) + self.offset

    def world_bounds(self) -> tuple[np.ndarray, np.ndarray]:
        flat = self.positions.reshape(-1, 3)
        return flat.min(0) + self.offset, flat.max(0) + self.offset


def object_from_soup(soup: TriangleSoup, key: object = 0, receiver: float = 1.0) -> SceneObject:
    """Flat-shaded SceneObject of a soup (face normals at every corner)."""
    normals, _ = face_normals_areas(soup.positions)
    flat = soup.positions.reshape(-1, 3)
    offset = 0.5 * (flat.min(0) + flat.max(0))
    return SceneObject(soup.name, key, (soup.positions - offset).astype(np.float32),
                       np.repeat(normals[:, None], 3, axis=1).astype(np.float32), receiver,
                       fill_class(soup.positions), offset=offset)


def scene_bounds(objects: list[SceneObject], boxes: list | None = None) -> tuple[np.ndarray, np.ndarray] | None:
    """World box (lo, hi) of all triangles, None when there are none. boxes: the objects'
    world_bounds() (None for empty objects) when the caller already has them."""
    if boxes is None:
        boxes = [o.world_bounds() if len(o.positions) else None for o in objects]
    boxes = [b for b in boxes if b is not None]
    if not boxes:
        return None
    return np.min([b[0] for b in boxes], axis=0), np.max([b[1] for b in boxes], axis=0)


def render_anchor(lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """A world point the GPU passes measure from, so float32 keeps its precision in scenes
    far from the origin: the box centre rounded to a multiple of the power of two above the
    box size (0 for anything that reaches its own size from the origin; stable while
    objects move within the box, so the object-space noise does not jump)."""
    lo, hi = np.asarray(lo, np.float64), np.asarray(hi, np.float64)
    extent = float(np.max(hi - lo))
    q = 2.0 ** np.ceil(np.log2(max(extent, 1e-9)))
    return np.round(0.5 * (lo + hi) / q) * q
