# SPDX-License-Identifier: GPL-3.0-or-later
"""The voxel grid of Hybrid Ambient Occlusion: its placement, and a CPU voxelization that
follows the GPU rasterization rule exactly (pure numpy).

Surface rule (shared with gpu_shaders/hao_voxelize.*): every triangle is projected along its
dominant normal axis a onto the plane of the other two axes (u, v); each voxel-column centre
(i + 1/2, j + 1/2) inside the projected triangle marks the one voxel containing the
triangle's point above it. Projecting along the dominant axis gives every triangle a
footprint of at least 1/sqrt(3) of its area, so no polygon vanishes edge-on (the paper's
artifact with axis-aligned polygons, which it hides by a random rotation of the grid).

Solid rule (objects that are closed, or nearly: see core/geometry.boundary_edge_fraction):
every triangle, projected along z, flips the voxels of each covered column whose centre lies
below it; an odd count of surfaces above a voxel centre means inside. Why: a surface
voxelization is one voxel thick, and a ray marched in a fixed number of steps longer than a
voxel steps over most of it (an 8-step ray with d_max = 25 voxels hits a one-voxel shell
about a third of the time), while a solid is hit whenever the ray spends a step inside it.
Flipping downwards (towards -z) puts the leaks of the usual scan holes (a bunny's open base)
below the object, inside the body or under it.

Bits are packed along z: texel (x, y, z // 32), bit z % 32, so a column flip touches at
most nz / 32 words.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

# (u, v, a) axis order per dominant axis a: a right-handed cycle, so (u, v) keeps orientation.
SWIZZLE = ((1, 2, 0), (2, 0, 1), (0, 1, 2))


@dataclass(frozen=True)
class GridSpec:
    """Cubic voxels of side `voxel` from `origin`; dims (nx, ny, nz), nz a multiple of 32
    (z is bit-packed 32 voxels per R32UI texel)."""
    origin: tuple[float, float, float]
    voxel: float
    dims: tuple[int, int, int]

    @property
    def words(self) -> tuple[int, int, int]:
        return (self.dims[0], self.dims[1], self.dims[2] // 32)

    def to_grid(self, points: np.ndarray) -> np.ndarray:
        """World points (..., 3) -> continuous grid coordinates (voxel units)."""
        return (np.asarray(points, np.float64) - np.asarray(self.origin)) / self.voxel


def grid_for_bounds(lo: np.ndarray, hi: np.ndarray, resolution: int) -> GridSpec:
    """Grid over the box [lo, hi] with `resolution` voxels along its longest side, padded by
    one voxel on each side so surfaces on the box faces are inside."""
    lo, hi = np.asarray(lo, np.float64), np.asarray(hi, np.float64)
    extent = float(np.max(hi - lo))
    if not np.isfinite(extent):
        raise ValueError("the region of interest has non-finite bounds")
    extent = max(extent, 1e-6)
    voxel = extent / (resolution - 2)
    dims = np.ceil((hi - lo) / voxel).astype(int) + 2
    dims = np.maximum(dims, 1)
    dims[2] = -(-dims[2] // 32) * 32
    centre = 0.5 * (lo + hi)
    origin = centre - 0.5 * dims * voxel
    return GridSpec(tuple(float(x) for x in origin), float(voxel), tuple(int(x) for x in dims))


def dominant_axes(positions: np.ndarray) -> np.ndarray:
    """Index 0/1/2 of the largest |normal| component of (F, 3, 3) triangles, (F,) int."""
    p = np.asarray(positions, np.float64)
    n = np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])
    return np.argmax(np.abs(n), axis=1)


def _column_samples(u: np.ndarray, v: np.ndarray, d: np.ndarray, eps: float):
    """Rasterize projected triangles at voxel-column centres, as the GPU does.

    u, v, d: (F, 3) corner coordinates in the projection plane and along the projection axis
    (voxel units). Yields, for each batch of (triangle, column) candidates in the triangles'
    bounding boxes: column indices (ci, cj), the interpolated depth, `inside` (strictly inside
    the triangle) and `near_edge` (within eps voxels of an edge line: the fill rule decides)."""
    area = (u[:, 1] - u[:, 0]) * (v[:, 2] - v[:, 0]) - (v[:, 1] - v[:, 0]) * (u[:, 2] - u[:, 0])
    keep = np.abs(area) > 1e-12  # edge-on in this projection: no column centre is covered
    u, v, d, area = u[keep], v[keep], d[keep], area[keep]
    i0 = np.floor(u.min(1) - 0.5).astype(int)
    j0 = np.floor(v.min(1) - 0.5).astype(int)
    wi = np.ceil(u.max(1) - 0.5).astype(int) - i0 + 1
    wj = np.ceil(v.max(1) - 0.5).astype(int) - j0 + 1
    lengths = [np.hypot(u[:, (k + 2) % 3] - u[:, (k + 1) % 3], v[:, (k + 2) % 3] - v[:, (k + 1) % 3]) for k in range(3)]
    for di in range(int(wi.max(initial=0))):
        for dj in range(int(wj.max(initial=0))):
            sel = (di < wi) & (dj < wj)
            if not sel.any():
                continue
            ci, cj = i0[sel] + di, j0[sel] + dj
            pu, pv = ci + 0.5, cj + 0.5
            uu, vv, dd, ar = u[sel], v[sel], d[sel], area[sel]
            # Barycentric weights from edge functions (the sign of the area folded in).
            w = [((uu[:, 1] - pu) * (vv[:, 2] - pv) - (vv[:, 1] - pv) * (uu[:, 2] - pu)) / ar,
                 ((uu[:, 2] - pu) * (vv[:, 0] - pv) - (vv[:, 2] - pv) * (uu[:, 0] - pu)) / ar]
            w.append(1.0 - w[0] - w[1])
            depth = w[0] * dd[:, 0] + w[1] * dd[:, 1] + w[2] * dd[:, 2]
            edge_dist = np.min([np.abs(w[k] * ar) / np.maximum(lengths[k][sel], 1e-30) for k in range(3)], axis=0)
            yield ci, cj, depth, np.min(w, axis=0) > 0.0, edge_dist < eps


def voxelize_reference(positions: np.ndarray, spec: GridSpec, eps: float = 2e-3) -> tuple[np.ndarray, np.ndarray]:
    """CPU voxelization by the surface rule above.

    positions: (F, 3, 3) world triangles. Returns (occupied, ambiguous), both (nz, ny, nx)
    bool: `ambiguous` marks voxels whose state depends on float rounding, where the GPU may
    differ: a column centre within eps voxels of a triangle edge (the fill rule decides), or
    a depth within eps voxels of a voxel boundary (the GPU interpolates in float32)."""
    g = spec.to_grid(positions)
    axes = dominant_axes(positions)
    nx, ny, nz = spec.dims
    occ = np.zeros((nz, ny, nx), bool)
    amb = np.zeros((nz, ny, nx), bool)
    up = np.array([0, 0, 1])
    for a in range(3):
        swizzle = SWIZZLE[a]
        t = g[axes == a]
        for ci, cj, depth, inside, near_edge in _column_samples(t[:, :, swizzle[0]], t[:, :, swizzle[1]],
                                                                t[:, :, swizzle[2]], eps):
            ck = np.floor(depth).astype(int)
            frac = depth - ck
            near_depth = (inside | near_edge) & ((frac < eps) | (frac > 1.0 - eps))
            column = np.stack([ci, cj, ck], 1)
            _mark(occ, column[inside], swizzle)
            _mark(amb, column[near_edge], swizzle)
            for shift in (-up, 0 * up, up):
                _mark(amb, column[near_depth] + shift, swizzle)
    return occ, amb


def _mark(target: np.ndarray, uva: np.ndarray, swizzle: tuple[int, int, int]) -> None:
    """Set target[z, y, x] for (n, 3) voxel coordinates given in (u, v, a) order."""
    if len(uva) == 0:
        return
    xyz = np.empty_like(uva)
    for k, axis in enumerate(swizzle):
        xyz[:, axis] = uva[:, k]
    nz, ny, nx = target.shape
    ok = ((xyz >= 0) & (xyz < np.array([nx, ny, nz]))).all(1)
    xyz = xyz[ok]
    target[xyz[:, 2], xyz[:, 1], xyz[:, 0]] = True


def solid_reference(positions: np.ndarray, spec: GridSpec, eps: float = 2e-3) -> tuple[np.ndarray, np.ndarray]:
    """CPU solid voxelization by the parity rule above: (inside, ambiguous), (nz, ny, nx)
    bool. Ambiguous: columns whose centre is within eps voxels of a projected edge (the whole
    column below may flip), and voxels whose centre is within eps of a crossing depth."""
    g = spec.to_grid(positions)
    nx, ny, nz = spec.dims
    flips = np.zeros((nz + 1, ny, nx), np.int32)  # difference array along z
    amb = np.zeros((nz, ny, nx), bool)
    for ci, cj, depth, inside, edge in _column_samples(g[:, :, 0], g[:, :, 1], g[:, :, 2], eps):
        ok = (ci >= 0) & (ci < nx) & (cj >= 0) & (cj < ny)
        count = np.clip(np.ceil(depth - 0.5), 0, nz).astype(int)  # voxels k < depth - 1/2
        flip = ok & inside
        np.add.at(flips, (np.zeros(flip.sum(), int), cj[flip], ci[flip]), 1)
        np.add.at(flips, (count[flip], cj[flip], ci[flip]), -1)
        amb[:, cj[ok & edge], ci[ok & edge]] = True
        frac = depth - 0.5 - np.floor(depth - 0.5)
        near = ok & (inside | edge) & ((frac < eps) | (frac > 1.0 - eps))
        for dk in (-1, 0):
            k = np.clip(count[near] + dk, 0, nz - 1)
            amb[k, cj[near], ci[near]] = True
    inside_count = np.cumsum(flips, axis=0)[:nz]
    return (inside_count % 2) == 1, amb


def pack_bits(occupied: np.ndarray) -> np.ndarray:
    """(nz, ny, nx) bool -> (nz // 32, ny, nx) uint32: bit z % 32 of word z // 32."""
    nz, ny, nx = occupied.shape
    bits = occupied.reshape(nz // 32, 32, ny, nx).astype(np.uint64)
    return (bits << np.arange(32, dtype=np.uint64)[None, :, None, None]).sum(axis=1).astype(np.uint32)


def unpack_bits(words: np.ndarray) -> np.ndarray:
    """Inverse of pack_bits: (nw, ny, nx) uint32 -> (nw * 32, ny, nx) bool."""
    nw, ny, nx = words.shape
    bits = (words[:, None] >> np.arange(32, dtype=np.uint32)[None, :, None, None]) & 1
    return bits.reshape(nw * 32, ny, nx).astype(bool)


# Occupancy pyramid (hierarchical traversal): level L is the grid max-pooled by 2^L per axis
# (a cell is occupied when any voxel in it is), bit-packed along z like level 0. On the GPU
# the levels sit side by side along x in one R32UI 3D texture (the atlas): level L at x
# offset level_offsets(dims)[L]. The coarsest level is the first whose longest side is at
# most PYRAMID_TOP_SIDE cells (MAX_LEVELS at most, a GLSL define).
MAX_LEVELS = 10
PYRAMID_TOP_SIDE = 4


def level_count(dims: tuple[int, int, int]) -> int:
    """Levels of the pyramid of a grid of dims (nx, ny, nz), level 0 included."""
    levels, side = 1, max(dims)
    while side > PYRAMID_TOP_SIDE and levels < MAX_LEVELS:
        side = -(-side // 2)
        levels += 1
    return levels


def level_dims(dims: tuple[int, int, int], level: int) -> tuple[int, int, int]:
    """(nx, ny, nz) cells of a level: ceil(n / 2^level) per axis."""
    return tuple(-(-int(n) // (1 << level)) for n in dims)


def level_offsets(dims: tuple[int, int, int]) -> list[int]:
    """x offset of each level in the atlas."""
    offsets, x = [], 0
    for level in range(level_count(dims)):
        offsets.append(x)
        x += level_dims(dims, level)[0]
    return offsets


def atlas_words(dims: tuple[int, int, int]) -> tuple[int, int, int]:
    """Texel size (x, y, z words) of the atlas holding every level of a grid of dims."""
    last = level_count(dims) - 1
    return (level_offsets(dims)[last] + level_dims(dims, last)[0], int(dims[1]), -(-int(dims[2]) // 32))


def occupancy_pyramid(occupied: np.ndarray) -> list[np.ndarray]:
    """(nz, ny, nx) bool -> [level 0, level 1, ...], each (nz_L, ny_L, nx_L) bool, the numpy
    twin of the GPU's pyramid pass (gpu_shaders/hao_pyramid.comp)."""
    levels = [np.asarray(occupied, bool)]
    dims = occupied.shape[::-1]
    for level in range(1, level_count(dims)):
        fine = levels[-1]
        nz, ny, nx = level_dims(dims, level)[::-1]
        padded = np.zeros((2 * nz, 2 * ny, 2 * nx), bool)
        padded[:fine.shape[0], :fine.shape[1], :fine.shape[2]] = fine
        levels.append(padded.reshape(nz, 2, ny, 2, nx, 2).any(axis=(1, 3, 5)))
    return levels
