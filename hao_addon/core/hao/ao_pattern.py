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
# A voxel is a cube, the surface in it a sheet through its middle: a ray that clips a voxel's
# corner would not meet the surface, and counting it made occluders half a voxel larger (a
# sphere on a plane: bias -0.0127 at D = 1.5 R with 1/50 R voxels, the dilation's -3 R^2 (h/2)
# / D^3 to the digit). A run of occupied voxels counts once the ray has run MIN_CHORD voxels
# inside it (measured there: -0.0057; a one-voxel sheet is crossed over at least 1/sqrt(3)).
MIN_CHORD = 0.6
# What the GPU passes that mirror this module get as defines (hao_ao.comp, near_field.comp).
GLSL_DEFINES = {"HAO_GOLDEN_FRACTION": GOLDEN_FRACTION, "HAO_SELF_OFFSET": SELF_OFFSET, "HAO_SELF_SLAB": SELF_SLAB,
                "HAO_MIN_CHORD": MIN_CHORD}


def pcg3d(v: np.ndarray) -> np.ndarray:
    """PCG3D hash (Jarzynski & Olano 2020) of (n, 3) uint32, as in gpu_shaders/pcg3d.glsl."""
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
                   planes: np.ndarray | None = None, slab: float = 0.0, min_chord: float = 0.0,
                   t_begin=0.0, exits: np.ndarray | None = None) -> np.ndarray:
    """Exact 3D-DDA (Amanatides & Woo) through a bool grid, in grid units (voxels of side 1
    from the grid's corner): starts (n, 3), unit dirs (n, 3), t_max (n,) or a scalar
    (np.inf: to the grid's exit). Returns (n,) float64: the ray parameter where the segment
    [0, t_max) enters the first occupied voxel it passes through (or passes that voxel's
    centre, where later), np.inf where none; with planes (n, 3) unit normals, only voxels
    whose centre lies more than `slab` above the plane through the start count; with
    min_chord, a run of counted voxels is a hit only once the ray has run that far inside it
    (its first voxel's distance is the hit). Every voxel the segment's interior crosses is
    visited, so none is stepped over; the GPU's hierarchical march (hao_march.glsl) must find
    the same voxel. t_begin: (n,) or a scalar, where the segment starts (the start point stays
    the plane's); exits: an (n,) array to receive where each segment left the grid's box (or
    t_max)."""
    occupied = np.asarray(occupied, bool)
    starts = np.asarray(starts, np.float64)
    dirs = np.asarray(dirs, np.float64)
    n = len(starts)
    dims = np.array(occupied.shape[::-1], np.float64)
    safe = np.where(dirs == 0.0, 1e-300, dirs)
    inv = 1.0 / safe
    t0, t1 = (0.0 - starts) * inv, (dims - starts) * inv
    t_in = np.maximum(np.minimum(t0, t1).max(axis=1), np.broadcast_to(np.asarray(t_begin, np.float64), (n,)))
    t_end = np.minimum(np.maximum(t0, t1).min(axis=1), np.broadcast_to(np.asarray(t_max, np.float64), (n,)))
    if exits is not None:
        exits[:] = t_end
    out = np.full(n, np.inf)
    step = np.where(dirs > 0.0, 1, -1)
    cell = np.clip(np.floor(starts + dirs * t_in[:, None]).astype(np.int64), 0, dims.astype(np.int64) - 1)
    t_next = np.where(dirs == 0.0, np.inf, ((cell + (step > 0)) - starts) * inv)
    t_delta = np.where(dirs == 0.0, np.inf, np.abs(inv))
    t_cur = t_in.copy()
    inside = np.zeros(n)  # length of the current run of counted voxels
    run_hit = np.zeros(n)  # the hit distance of the run's first voxel
    live = np.flatnonzero(t_in < t_end)
    rows = np.arange(n)
    while len(live):
        c = cell[live]
        counted = occupied[c[:, 2], c[:, 1], c[:, 0]]
        if planes is not None:
            counted &= np.einsum("ij,ij->i", c + 0.5 - starts[live], planes[live]) > slab
        # A counted voxel's hit distance: its centre's along the ray (a surface runs through a
        # voxel's middle on average), never before its entry; a run of them is a hit once the
        # ray has run min_chord inside them.
        centre_t = np.maximum(t_cur[live], np.einsum("ij,ij->i", c + 0.5 - starts[live], dirs[live]))
        chord = t_next[live].min(axis=1) - t_cur[live]
        run_hit[live] = np.where(counted & (inside[live] == 0.0), centre_t, run_hit[live])
        inside[live] = np.where(counted, inside[live] + chord, 0.0)
        hit = counted & (inside[live] >= min_chord)
        out[live[hit]] = run_hit[live[hit]]
        live = live[~hit]
        axis = np.argmin(t_next[live], axis=1)
        r = rows[live]
        t_cur[r] = t_next[r, axis]
        cell[r, axis] += step[r, axis]
        t_next[r, axis] += t_delta[r, axis]
        within = ((cell[r] >= 0) & (cell[r] < dims.astype(np.int64))).all(axis=1)
        live = live[within & (t_cur[r] < t_end[r])]
    return out


def march_reference(occupied: np.ndarray, origin: np.ndarray, voxel: float, points: np.ndarray,
                    normals: np.ndarray, rays: int, steps: int, spread: float, max_distance: float,
                    march: str = "fixed", falloff: str = "wendland") -> np.ndarray:
    """Accessibility (n,) at (n, 3) points with unit normals against an (nz, ny, nx) bool
    grid, by the GPU's rules (see the module docstring). march: 'fixed' (the paper's
    `steps` samples) or 'hierarchical' (every voxel on the ray, exact DDA: the GPU's budget of
    `steps` traversal steps is assumed large enough; points outside the grid get 1);
    max_distance <= 0: unlimited (rays run to the grid's exit and every hit occludes fully)."""
    if march == "hierarchical":  # one grid is one cascade
        return cascade_march_reference([(occupied, np.asarray(origin), voxel)], points, normals, rays, spread,
                                       max_distance, falloff)
    points = np.asarray(points, np.float64)
    normals = np.asarray(normals, np.float64)
    jitter = point_jitter(points, voxel)
    dirs = ray_directions(normals, jitter, rays, spread)
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


def cascade_march_reference(grids: list[tuple[np.ndarray, np.ndarray, float]], points: np.ndarray,
                            normals: np.ndarray, rays: int, spread: float, max_distance: float,
                            falloff: str = "wendland") -> np.ndarray:
    """The hierarchical march over cascades (hao_ao.comp), exact DDA: grids (occupied (nz, ny,
    nx) bool, origin (3,), voxel) finest first, each inside the next. A point's rays start in
    the finest grid holding it (its voxel also seeds the jitter) and continue in the next
    coarser one from where they leave a grid's box. Points outside every grid get 1.
    Returns (n,) accessibility."""
    points = np.asarray(points, np.float64)
    normals = np.asarray(normals, np.float64)
    out = np.ones(len(points))
    first = np.full(len(points), -1)
    for k in range(len(grids) - 1, -1, -1):
        occupied, origin, voxel = grids[k]
        g = (points - np.asarray(origin)) / voxel
        first[np.all((g >= 0.0) & (g < np.array(occupied.shape[::-1])), axis=1)] = k
    for k0 in range(len(grids)):
        sel = np.flatnonzero(first == k0)
        if not len(sel):
            continue
        jitter = point_jitter(points[sel], grids[k0][2])
        dirs = ray_directions(normals[sel], jitter, rays, spread).reshape(-1, 3)
        pts = np.repeat(points[sel], rays, axis=0)
        planes = np.repeat(normals[sel], rays, axis=0)
        hit = np.full(len(pts), np.inf)
        travelled = np.zeros(len(pts))
        for occupied, origin, voxel in grids[k0:]:
            live = np.isinf(hit) & ((travelled < max_distance) if max_distance > 0.0 else True)
            if not live.any():
                break
            t_max = max_distance / voxel if max_distance > 0.0 else np.inf
            exits = np.empty(int(live.sum()))
            t = dda_first_hits(occupied, (pts[live] - np.asarray(origin)) / voxel, dirs[live], t_max, planes[live],
                               SELF_SLAB, MIN_CHORD, travelled[live] / voxel, exits)
            hit[live] = t * voxel
            travelled[live] = np.maximum(travelled[live], exits * voxel)
        occlusion = occlusion_weight(hit, max_distance, falloff).reshape(len(sel), rays)
        out[sel] = 1.0 - occlusion.mean(axis=1)
    return out


def fixed_march_reach(shape: tuple[int, int, int], voxel: float) -> float:
    """The fixed march's reach at unlimited distance: the grid's diagonal."""
    return float(np.linalg.norm(shape)) * voxel
