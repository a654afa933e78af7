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

from ..kernels import wendland

GOLDEN_FRACTION = 0.6180339887498949
SELF_OFFSET = 1.75  # voxels; > sqrt(3)
# What the GPU passes that mirror this module get as defines (hao_ao.comp, near_field.comp).
GLSL_DEFINES = {"HAO_GOLDEN_FRACTION": GOLDEN_FRACTION, "HAO_SELF_OFFSET": SELF_OFFSET}


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


def march_reference(occupied: np.ndarray, origin: np.ndarray, voxel: float, points: np.ndarray,
                    normals: np.ndarray, rays: int, steps: int, spread: float, max_distance: float) -> np.ndarray:
    """Accessibility (n,) at (n, 3) points with unit normals against an (nz, ny, nx) bool
    grid, by exactly the GPU's rule (see the module docstring)."""
    points = np.asarray(points, np.float64)
    normals = np.asarray(normals, np.float64)
    jitter = point_jitter(points, voxel)
    dirs = ray_directions(normals, jitter, rays, spread)
    offset = SELF_OFFSET * voxel
    start = points + normals * offset
    nz, ny, nx = occupied.shape
    hit_t = np.full(dirs.shape[:2], np.inf)
    for j in range(steps - 1, -1, -1):  # last to first: the first hit wins
        t = max_distance * (j + jitter[:, 2:3]) / steps
        q = start[:, None] + dirs * t[..., None]
        g = np.floor((q - np.asarray(origin)) / voxel).astype(np.int64)
        inside = ((g >= 0) & (g < np.array([nx, ny, nz]))).all(-1)
        occ = np.zeros(inside.shape, bool)
        gi = g[inside]
        occ[inside] = occupied[gi[:, 2], gi[:, 1], gi[:, 0]]
        hit_t = np.where(occ, np.broadcast_to(t, hit_t.shape) + offset, hit_t)
    w = np.where(np.isfinite(hit_t), wendland(np.where(np.isfinite(hit_t), hit_t, 0.0), max_distance), 0.0)
    return 1.0 - w.mean(axis=1)
