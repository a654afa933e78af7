# SPDX-License-Identifier: GPL-3.0-or-later
"""UDIM tiles: a UV map whose islands lie in several unit squares of UV space bakes one map
per used tile (tile 1001 + u + 10 v for the square [u, u + 1) x [v, v + 1), u in 0..9),
each with its own margins, as Blender's tiled images and Cycles' bake hold them.

A layout is tiled only when every triangle lies inside one tile of Blender's grid (1001 to
2000) and some tile is not 1001;
a triangle that crosses a tile border keeps the single-tile bake of 0..1 and its warning
about UVs outside it (core/bake/uv_checks.py), as before UDIM support.
"""
from __future__ import annotations

import os
from dataclasses import dataclass

import numpy as np

FIRST_TILE = 1001
TILES_PER_ROW = 10
# Blender's tiles end at 2000 (v below 100): a layout reaching past it is not tiled.
TILE_ROWS = 100
# UVs this far past a tile's border still lie in it (float rounding of islands packed to
# the edge).
BORDER_SLACK = 1e-6
UDIM_TOKEN = "<UDIM>"


@dataclass
class UdimLayout:
    """tiles (T,) int64 the UDIM numbers used, ascending; face_tile (F,) int64 each
    triangle's index into tiles; offsets (T, 2) float64 each tile's low UV corner."""

    tiles: np.ndarray
    face_tile: np.ndarray
    offsets: np.ndarray

    @property
    def count(self) -> int:
        return len(self.tiles)

    def faces(self, tile: int) -> np.ndarray:
        """(k,) int64 the triangles of tile index `tile`."""
        return np.flatnonzero(self.face_tile == tile)

    def local_uvs(self, uvs: np.ndarray, tile: int) -> tuple[np.ndarray, np.ndarray]:
        """(faces (k,) int64 of tile index `tile`, their UVs (k, 3, 2) moved into 0..1)."""
        faces = self.faces(tile)
        return faces, uvs[faces] - self.offsets[tile]


def tile_number(u: np.ndarray, v: np.ndarray) -> np.ndarray:
    """UDIM numbers of integer tile coordinates."""
    return FIRST_TILE + np.asarray(u, np.int64) + TILES_PER_ROW * np.asarray(v, np.int64)


def udim_layout(uvs: np.ndarray) -> UdimLayout | None:
    """The tiles of a UV layout (F, 3, 2), or None where it bakes as one 0..1 map."""
    uvs = np.asarray(uvs, np.float64)
    if len(uvs) == 0:
        return None
    corner = np.floor(uvs.mean(axis=1)).astype(np.int64)  # (F, 2) the tile of each centroid
    inside = ((uvs >= corner[:, None, :] - BORDER_SLACK) & (uvs <= corner[:, None, :] + 1 + BORDER_SLACK)).all(axis=(1, 2))
    if not inside.all() or (corner == 0).all():
        return None
    if corner.min() < 0 or corner[:, 0].max() >= TILES_PER_ROW or corner[:, 1].max() >= TILE_ROWS:
        return None  # outside the UDIM grid (u in 0..9, v in 0..99): not a tiled layout
    numbers = tile_number(corner[:, 0], corner[:, 1])
    tiles, face_tile = np.unique(numbers, return_inverse=True)
    offsets = np.stack([(tiles - FIRST_TILE) % TILES_PER_ROW, (tiles - FIRST_TILE) // TILES_PER_ROW], axis=1)
    return UdimLayout(tiles.astype(np.int64), face_tile.astype(np.int64), offsets.astype(np.float64))


def tile_path(path: str, tile: int) -> str:
    """The file of one tile: <UDIM> in path becomes its number; without the token, '.<number>'
    goes before the extension (name.1001.png, as Blender names tiles)."""
    if UDIM_TOKEN in path:
        return path.replace(UDIM_TOKEN, str(int(tile)))
    stem, ext = os.path.splitext(path)
    return f"{stem}.{int(tile)}{ext}"
