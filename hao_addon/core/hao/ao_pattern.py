# SPDX-License-Identifier: GPL-3.0-or-later
"""Per-pixel ray pattern of Hybrid Ambient Occlusion and a numpy mirror of the GPU voxel
ray-march (gpu_shaders/hao_common.glsl, hao_ao.comp), used to test the compute pass
(pure numpy).

Pattern: N rays, cosine-distributed and regular: ray i has sin^2(theta) = s_i sin^2(theta_max)
with s_i = (i + u) / N, and azimuth 2 pi (i * 0.6180339887 + r) (a golden-angle spiral).
theta_max = spread * pi / 2, so spread 1 covers the hemisphere and an unoccluded pixel sums to
exactly N. The jitter (r, u, step offset) is a hash of the surface point's cell in object space
(cells of one voxel): a surface point keeps its rays whatever the camera does, so the noise
does not swim (the paper's tiled 3D noise texture, here a hash: no texture to bind).

March: from o = p + n * offset, S samples at t_j = d_max (j + u_s) / S; the first occupied
voxel ends the ray with occlusion w(t_j + offset, d_max) (Wendland, equation 3). Accessibility
A = 1 - mean over rays of the occlusion (cosine weighting is in the distribution).
Self-intersection: every voxel marked for a plane through p lies within sqrt(3) voxels of it,
so an origin SELF_OFFSET = 1.75 voxels along the normal starts every ray of a flat receiver
outside its own voxels, and a lone plane gets A = 1 exactly (tested).
"""
from __future__ import annotations

import numpy as np

from ..kernels import occlusion_weight

GOLDEN_FRACTION = 0.6180339887498949
SELF_OFFSET = 1.75  # voxels; > sqrt(3)
# The hierarchical march starts on the surface and ignores occupied voxels whose centre lies
# within this many voxels above the receiver's tangent plane: its own surface's voxels have
# centres within sqrt(3)/2 = 0.87 of it; the rest allows for a shading normal tilted from
# the face.
SELF_SLAB = 1.0
# What the GPU passes that mirror this module get as defines (hao_ao.comp, near_field.comp).
GLSL_DEFINES = {"HAO_GOLDEN_FRACTION": GOLDEN_FRACTION, "HAO_SELF_OFFSET": SELF_OFFSET, "HAO_SELF_SLAB": SELF_SLAB}


def pcg3d(v: np.ndarray) -> np.ndarray:
    """PCG3D hash (Jarzynski & Olano 2020) of (n, 3) uint32, as in hao_common.glsl."""
    v = np.array(v, dtype=np.uint32, copy=True)
    with np.errstate(over="ignore"):
        v = v * np.uint32(1664525) + np.uint32(1013904223)
        v[:, 0] += v[:, 1] * v[:, 2]
        v[:, 1] += v[:, 2] * v[:, 0]
        v[:, 2] += v[:, 0] * v[:, 1]
        v ^= v >> np.uint32(16)
        v[:, 0] += v[:, 1] * v[:, 2]
        v[:, 1] += v[:, 2] * v[:, 0]
        v[:, 2] += v[:, 0] * v[:, 1]
    return v


def point_jitter(points: np.ndarray, cell: float) -> np.ndarray:
    """(n, 3) world points -> (n, 3) floats in [0, 1): azimuth, radial and step jitter."""
    key = np.floor(np.asarray(points, np.float64) / cell).astype(np.int64).astype(np.uint32)
    return pcg3d(key).astype(np.float64) / 4294967296.0


def tangent_frames(normals: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Branchless orthonormal basis (Duff et al. 2017) for (n, 3) unit normals."""
    n = np.asarray(normals, np.float64)
    sign = np.where(n[:, 2] >= 0.0, 1.0, -1.0)
    a = -1.0 / (sign + n[:, 2])
    b = n[:, 0] * n[:, 1] * a
    t = np.stack([1.0 + sign * n[:, 0] ** 2 * a, sign * b, -sign * n[:, 0]], 1)
    s = np.stack([b, sign + n[:, 1] ** 2 * a, -n[:, 1]], 1)
    return t, s


def ray_directions(normals: np.ndarray, jitter: np.ndarray, rays: int, spread: float) -> np.ndarray:
    """(n, rays, 3) world directions of the pattern for (n, 3) normals and jitters."""
    t, s = tangent_frames(normals)
    i = np.arange(rays)[None, :]
    sin_max2 = np.sin(spread * np.pi / 2.0) ** 2
    r2 = (i + jitter[:, 1:2]) / rays * sin_max2
    phi = 2.0 * np.pi * (i * GOLDEN_FRACTION + jitter[:, 0:1])
    r = np.sqrt(r2)
    z = np.sqrt(np.maximum(1.0 - r2, 0.0))
    return (r * np.cos(phi))[..., None] * t[:, None] + (r * np.sin(phi))[..., None] * s[:, None] \
        + z[..., None] * np.asarray(normals, np.float64)[:, None]


def dda_first_hits(occupied: np.ndarray, starts: np.ndarray, dirs: np.ndarray, t_max,
                   planes: np.ndarray | None = None, slab: float = 0.0) -> np.ndarray:
    """Exact 3D-DDA (Amanatides & Woo) through a bool grid, in grid units (voxels of side 1
    from the grid's corner): starts (n, 3), unit dirs (n, 3), t_max (n,) or a scalar
    (np.inf: to the grid's exit). Returns (n,) float64: the ray parameter where the segment
    [0, t_max) enters the first occupied voxel it passes through (or passes that voxel's
    centre, where later), np.inf where none; with
    planes (n, 3) unit normals, only voxels whose centre lies more than `slab` above the plane
    through the start count. Every voxel the segment's interior crosses is visited, so none is
    stepped over; the GPU's hierarchical march (hao_march.glsl) must find the same voxel."""
    occupied = np.asarray(occupied, bool)
    starts = np.asarray(starts, np.float64)
    dirs = np.asarray(dirs, np.float64)
    n = len(starts)
    dims = np.array(occupied.shape[::-1], np.float64)
    safe = np.where(dirs == 0.0, 1e-300, dirs)
    inv = 1.0 / safe
    t0, t1 = (0.0 - starts) * inv, (dims - starts) * inv
    t_in = np.maximum(np.minimum(t0, t1).max(axis=1), 0.0)
    t_end = np.minimum(np.maximum(t0, t1).min(axis=1), np.broadcast_to(np.asarray(t_max, np.float64), (n,)))
    out = np.full(n, np.inf)
    step = np.where(dirs > 0.0, 1, -1)
    cell = np.clip(np.floor(starts + dirs * t_in[:, None]).astype(np.int64), 0, dims.astype(np.int64) - 1)
    t_next = np.where(dirs == 0.0, np.inf, ((cell + (step > 0)) - starts) * inv)
    t_delta = np.where(dirs == 0.0, np.inf, np.abs(inv))
    t_cur = t_in.copy()
    live = np.flatnonzero(t_in < t_end)
    rows = np.arange(n)
    while len(live):
        c = cell[live]
        hit = occupied[c[:, 2], c[:, 1], c[:, 0]]
        if planes is not None:
            hit &= np.einsum("ij,ij->i", c + 0.5 - starts[live], planes[live]) > slab
        # The hit distance: the voxel centre's along the ray (a surface runs through a voxel's
        # middle on average), never before the voxel's entry.
        centre_t = np.einsum("ij,ij->i", c + 0.5 - starts[live], dirs[live])
        out[live[hit]] = np.maximum(t_cur[live[hit]], centre_t[hit])
        live = live[~hit]
        axis = np.argmin(t_next[live], axis=1)
        r = rows[live]
        t_cur[r] = t_next[r, axis]
        cell[r, axis] += step[r, axis]
        t_next[r, axis] += t_delta[r, axis]
        inside = ((cell[r] >= 0) & (cell[r] < dims.astype(np.int64))).all(axis=1)
        live = live[inside & (t_cur[r] < t_end[r])]
    return out


def march_reference(occupied: np.ndarray, origin: np.ndarray, voxel: float, points: np.ndarray,
                    normals: np.ndarray, rays: int, steps: int, spread: float, max_distance: float,
                    march: str = "fixed", falloff: str = "wendland") -> np.ndarray:
    """Accessibility (n,) at (n, 3) points with unit normals against an (nz, ny, nx) bool
    grid, by the GPU's rules (see the module docstring). march: 'fixed' (the paper's
    `steps` samples) or 'hierarchical' (every voxel on the ray, exact DDA: the GPU's budget of
    `steps` traversal steps is assumed large enough); max_distance <= 0: unlimited (rays run
    to the grid's exit and every hit occludes fully)."""
    points = np.asarray(points, np.float64)
    normals = np.asarray(normals, np.float64)
    jitter = point_jitter(points, voxel)
    dirs = ray_directions(normals, jitter, rays, spread)
    if march == "hierarchical":
        t_max = max_distance / voxel if max_distance > 0.0 else np.inf
        grid_start = (np.repeat(points, rays, axis=0) - np.asarray(origin)) / voxel
        hit_t = dda_first_hits(occupied, grid_start, dirs.reshape(-1, 3), t_max, np.repeat(normals, rays, axis=0),
                               SELF_SLAB).reshape(len(points), rays)
        return 1.0 - occlusion_weight(hit_t * voxel, max_distance, falloff).mean(axis=1)
    offset = SELF_OFFSET * voxel
    start = points + normals * offset
    reach = max_distance if max_distance > 0.0 else fixed_march_reach(occupied.shape, voxel)
    nz, ny, nx = occupied.shape
    hit_t = np.full(dirs.shape[:2], np.inf)
    for j in range(steps - 1, -1, -1):  # last to first: the first hit wins
        t = reach * (j + jitter[:, 2:3]) / steps
        q = start[:, None] + dirs * t[..., None]
        g = np.floor((q - np.asarray(origin)) / voxel).astype(np.int64)
        inside = ((g >= 0) & (g < np.array([nx, ny, nz]))).all(-1)
        occ = np.zeros(inside.shape, bool)
        gi = g[inside]
        occ[inside] = occupied[gi[:, 2], gi[:, 1], gi[:, 0]]
        hit_t = np.where(occ, np.broadcast_to(t, hit_t.shape) + offset, hit_t)
    return 1.0 - occlusion_weight(hit_t, max_distance, falloff).mean(axis=1)


def fixed_march_reach(shape: tuple[int, int, int], voxel: float) -> float:
    """The fixed march's reach at unlimited distance: the grid's diagonal."""
    return float(np.linalg.norm(shape)) * voxel
