# SPDX-License-Identifier: GPL-3.0-or-later
"""Receivers: the surface points a bake estimates AO at, each with the texel it adds to.

A map's value at a texel is the ratio of its receivers' summed (V w, w) terms (core/bake/plan.py,
plan_weights.shading_corners), so one bake design serves every kind of receiver:
- the texel centres of the target's UV layout (what the gather's GPU texel list holds),
- stratified sub-texel points of it (anti-aliasing, samples_per_texel > 1),
- points on high-poly sources that the low-poly's texels project to (core/bake/projection.py),
- the target's face corners, each adding to its vertex or corner (core/bake/vertex_target.py).
A UDIM layout's texel indices run over its tiles (core/bake/udim.py).
The gather uploads a Receivers list as its texel list; the reference baker traces from it.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .terminator import smooth_surface_lift
from .udim import UdimLayout
from .uv_raster import texel_surface_samples


@dataclass
class Receivers:
    """points: (n, 3) float64 normalized positions; geometric: (n, 3) unit normals of the true
    surface (rays start off it, directions below it are occluded); shading: (n, 3) unit
    normals the hemisphere and the cosine weight are about; inv_s: (n,) a positive scale of the
    receiver's weights, 1 / S where the plan knows it (S the hemisphere weight sum of the
    shading normal; it keeps the GPU's float32 sums near 1), else 1: it cancels, because
    every receiver is normalized by its own weight sum (estimators.texel_sums); 0: never lit,
    left out; texel: (n,)
    int64 flat texel index y * size + x; lift: (n, 3) normalized, Cycles' terminator lift of
    ray starts at full amount (core/bake/terminator.py), or None where nothing is lifted (flat
    shading, or the offset off)."""

    points: np.ndarray
    geometric: np.ndarray
    shading: np.ndarray
    inv_s: np.ndarray
    texel: np.ndarray
    lift: np.ndarray | None = None

    def __len__(self) -> int:
        return len(self.points)

    def subset(self, keep: np.ndarray) -> "Receivers":
        return Receivers(self.points[keep], self.geometric[keep], self.shading[keep], self.inv_s[keep],
                         self.texel[keep], None if self.lift is None else self.lift[keep])


def sub_texel_grid(samples_per_texel: int) -> int:
    """Points per texel side: 1, 2, 3 or 4 for 1, 4, 9 or 16 samples per texel."""
    side = math.isqrt(samples_per_texel)
    if side * side != samples_per_texel or side < 1:
        raise ValueError(f"samples per texel must be a square (1, 4, 9, 16), got {samples_per_texel}")
    return side


def texel_sample_points(uvs: np.ndarray, size: int, samples_per_texel: int = 1
                        ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Stratified points of every texel a UV triangle covers: the centres of a k x k grid
    inside the texel (k^2 = samples_per_texel; k = 1 is the texel centre).

    uvs: (F, 3, 2). Returns (texel (m,) int64 flat index y * size + x, face (m,) int64,
    bary (m, 3) float64) for the points inside some triangle (the first one, where UV
    islands overlap)."""
    k = sub_texel_grid(samples_per_texel)
    face, bary, _hits = texel_surface_samples(np.asarray(uvs, np.float64), size * k)
    ys, xs = np.nonzero(face >= 0)
    texel = (ys // k) * size + xs // k
    return texel.astype(np.int64), face[ys, xs], bary[ys, xs]


def tiled_sample_points(uvs: np.ndarray, size: int, samples_per_texel: int = 1, tiles: UdimLayout | None = None
                        ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """texel_sample_points() of every UDIM tile of a layout (tiles None: the 0..1 tile), each
    tile's triangles moved into 0..1; texel indices are tile * size^2 + y * size + x."""
    if tiles is None:
        return texel_sample_points(uvs, size, samples_per_texel)
    parts = []
    for tile in range(tiles.count):
        faces, local = tiles.local_uvs(uvs, tile)
        texel, face, bary = texel_sample_points(local, size, samples_per_texel)
        parts.append((texel + tile * size * size, faces[face], bary))
    return tuple(np.concatenate(column) for column in zip(*parts))


def interpolate_unit(corners: np.ndarray, face: np.ndarray, bary: np.ndarray) -> np.ndarray:
    """(m, 3) unit vectors: corners (F, 3, 3) interpolated at (face (m,), bary (m, 3))."""
    v = np.einsum("mk,mkd->md", bary, corners[face].astype(np.float64))
    return v / np.maximum(np.linalg.norm(v, axis=1, keepdims=True), 1e-30)


# faces_touching marks cells on a grid at most this fine (a face reaching a marked grid cell
# is kept: a few more faces than those reaching the texels themselves, at a summed-area
# table's cost that does not grow with the map: 0.18 s a call at 2048^2 on the texels).
TOUCH_GRID = 512


def faces_touching(uvs: np.ndarray, size: int, cells: np.ndarray) -> np.ndarray:
    """(k,) int64 the faces whose UV box (grown by a texel) reaches a cell of a TOUCH_GRID
    raster that holds one of cells (flat y * size + x of one 0..1 tile): every face that can
    put a sample point into them, and a few beside, in face order."""
    grid = min(size, TOUCH_GRID)
    cells = np.asarray(cells, np.int64)
    coarse = (cells // size * grid // size) * grid + cells % size * grid // size
    mark = np.zeros((grid + 1, grid + 1), np.int32)  # a summed-area table of the marked cells
    mark[1:, 1:] = np.bincount(coarse, minlength=grid * grid).reshape(grid, grid) > 0
    table = mark.cumsum(0).cumsum(1)
    p = uvs * size
    lo = np.clip((np.floor(p.min(axis=1)) - 1) * grid // size, 0, grid).astype(np.int64)
    hi = np.clip(-(-(np.ceil(p.max(axis=1)) + 1) * grid // size) + 1, 0, grid).astype(np.int64)
    inside = table[hi[:, 1], hi[:, 0]] - table[lo[:, 1], hi[:, 0]] - table[hi[:, 1], lo[:, 0]] + table[lo[:, 1], lo[:, 0]]
    return np.flatnonzero(inside > 0)


def uv_receivers(positions: np.ndarray, uvs: np.ndarray, faces: np.ndarray, corners: np.ndarray, size: int,
                 samples_per_texel: int = 1, lift: bool = False, tiles: UdimLayout | None = None,
                 cells: np.ndarray | None = None) -> Receivers:
    """The target's own surface at the sample points of its UV layout (BakePlan fields:
    positions (F, 3, 3) normalized, uvs (F, 3, 2), faces (F, 4) normal and 1 / S_f, corners
    (F, 3, 4) shading normal and 1 / S). Faces never lit are left out. 1 / S is interpolated
    like the GPU passes interpolate it. lift: with Cycles' terminator lift of each point.
    tiles: the UDIM tiles of a tiled layout (texel tile * size^2 + y * size + x). cells: only
    these texels' points (of one 0..1 tile), rasterizing only the faces that reach them."""
    if cells is not None and tiles is None:
        subset = faces_touching(uvs, size, cells)
        texel, face, bary = texel_sample_points(uvs[subset], size, samples_per_texel)
        keep = np.isin(texel, cells)
        return receivers_at(positions, faces, corners, texel[keep], subset[face[keep]], bary[keep], lift)
    texel, face, bary = tiled_sample_points(uvs, size, samples_per_texel, tiles)
    return receivers_at(positions, faces, corners, texel, face, bary, lift)


def receivers_at(positions: np.ndarray, faces: np.ndarray, corners: np.ndarray, texel: np.ndarray,
                 face: np.ndarray, bary: np.ndarray, lift: bool = False) -> Receivers:
    """Receivers at surface points (face (m,), bary (m, 3)) adding to `texel` (m,) (BakePlan
    fields as uv_receivers); points on faces never lit are left out."""
    lit = faces[face, 3] > 0.0
    texel, face, bary = texel[lit], face[lit], bary[lit]
    points = np.einsum("mk,mkd->md", bary, positions[face].astype(np.float64))
    shading = interpolate_unit(corners[..., :3], face, bary)
    inv_s = np.einsum("mk,mk->m", bary, corners[face, :, 3].astype(np.float64))
    geometric = faces[face, :3].astype(np.float64)
    lifts = None
    if lift:
        lifts = smooth_surface_lift(positions[face].astype(np.float64), corners[face, :, :3].astype(np.float64),
                                    bary, geometric)
    return Receivers(points, geometric, shading, inv_s, texel, lifts)


def corner_receivers(faces: np.ndarray, positions: np.ndarray, corners: np.ndarray, cells: np.ndarray,
                     lift: bool = False) -> Receivers:
    """The target's face corners whose cell (F, 3) int64 is not -1, at their vertex with the
    corner's own shading normal and 1 / S (BakePlan fields: faces (F, 4), positions (F, 3, 3)
    normalized, corners (F, 3, 4)); `texel` is the cell. Faces never lit are left out. lift:
    with Cycles' terminator lift (zero at a vertex, where the smooth surface meets the facet;
    kept for the receivers' one layout)."""
    keep = (cells >= 0) & (faces[:, 3] > 0.0)[:, None]
    face, corner = np.nonzero(keep)
    bary = np.eye(3)[corner]
    geometric = faces[face, :3].astype(np.float64)
    lifts = None
    if lift:
        lifts = smooth_surface_lift(positions[face].astype(np.float64), corners[face, :, :3].astype(np.float64),
                                    bary, geometric)
    shading = corners[face, corner, :3].astype(np.float64)
    shading /= np.maximum(np.linalg.norm(shading, axis=1, keepdims=True), 1e-30)
    return Receivers(positions[face, corner].astype(np.float64), geometric, shading,
                     corners[face, corner, 3].astype(np.float64), cells[face, corner].astype(np.int64), lifts)
