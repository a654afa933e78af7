# SPDX-License-Identifier: GPL-3.0-or-later
"""Texture sets: several objects, each with its own UVs, baked into one shared image (what
Cycles does when the selected objects' materials share one image node). The objects become
one target: every texel is a receiver of the same directions, each object occludes the
others. Their islands must not overlap across objects (each texel belongs to one surface);
overlap within one object is the usual warning (core/bake/uv_checks.py).
"""
from __future__ import annotations

import numpy as np

from ..errors import BakeInputError
from ..geometry import TriangleSoup, face_normals_areas
from .uv_checks import CHECK_SIDE, texel_centre_hits

# Texels where two objects' islands may meet before the set is refused (rasterized edge
# rounding where islands are packed against each other), as a fraction of the smaller one.
OVERLAP_TOLERANCE = 0.002


def cross_object_overlaps(parts: list[TriangleSoup], size: int) -> list[tuple[str, str, float]]:
    """(name a, name b, fraction of the smaller one's texels) of every pair of parts whose UV
    islands cover the same texel centres beyond OVERLAP_TOLERANCE (at min(size, CHECK_SIDE)),
    UDIM tiles included (texels of different tiles never overlap)."""
    side = min(int(size), CHECK_SIDE)
    covers = []  # per part: the sorted keys of the texel centres it covers, (tile, texel) in one int64
    for part in parts:
        tiles = np.floor(part.uvs.mean(axis=1)).astype(np.int64)
        keys = []
        for tile in np.unique(tiles, axis=0):
            hit = np.flatnonzero(texel_centre_hits(part.uvs[(tiles == tile).all(axis=1)] - tile, side).ravel() > 0)
            keys.append(((tile[0] * 100_003 + tile[1]) * side * side) + hit)
        covers.append(np.unique(np.concatenate(keys)))
    found = []
    for a in range(len(parts)):
        for b in range(a + 1, len(parts)):
            shared = len(np.intersect1d(covers[a], covers[b], assume_unique=True))
            smaller = max(1, min(len(covers[a]), len(covers[b])))
            if shared > OVERLAP_TOLERANCE * smaller:
                found.append((parts[a].name, parts[b].name, shared / smaller))
    return found


def texture_set_target(parts: list[TriangleSoup], size: int, name: str = "texture set") -> TriangleSoup:
    """One target of the parts (each with UVs), their shading normals kept (face normals for a
    flat part beside smooth ones). Raises BakeInputError naming the objects whose islands
    overlap."""
    if not parts:
        raise BakeInputError("a texture set needs at least one mesh")
    missing = [p.name for p in parts if p.uvs is None]
    if missing:
        raise BakeInputError(f"a texture set bakes into the objects' own UVs: {', '.join(missing)} has none")
    overlaps = cross_object_overlaps(parts, size)
    if overlaps:
        listed = "; ".join(f"'{a}' and '{b}' ({100 * f:.1f} % of the texels)" for a, b, f in overlaps)
        raise BakeInputError(f"UV islands of different objects overlap in the shared image: {listed}; "
                             f"move them apart (or bake the objects into images of their own)")
    normals = None
    if any(p.normals is not None for p in parts):
        normals = np.concatenate([p.normals if p.normals is not None
                                  else np.repeat(face_normals_areas(p.positions)[0][:, None, :], 3, axis=1)
                                  for p in parts])
    return TriangleSoup(np.concatenate([p.positions for p in parts]), np.concatenate([p.uvs for p in parts]),
                        name, normals)
