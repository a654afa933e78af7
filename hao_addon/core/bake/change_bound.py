# SPDX-License-Identifier: GPL-3.0-or-later
"""How much an edit inside a sphere can change a receiver's ambient occlusion: the bound an
incremental re-bake (hao_addon/rebake.py) keeps texels by.

The derivation. A receiver at p with normal n bakes A = (1/N) integral over the hemisphere of
V(w) W(n . w) dw, W the weighting (cosine: n . w; uniform: 1), inside the spread cone
(n . w >= cos a) where it is set, N the same integral with V = 1. Geometry inside a ball of
radius r whose centre is D > r away can only change V for directions inside the cone of
half-angle t, sin t = r / D, towards the ball's centre, and by at most 1 there; a falloff
weighs a change by at most 1 too. So |dA| is at most that cone's share of N, largest when the
cone points along n:

    cosine:  (pi sin^2 t) / (pi sin^2 a) = (r / D)^2 / sin^2 a
    uniform: 2 pi (1 - cos t) / (2 pi (1 - cos a)) = (1 - cos t) / (1 - cos a)

both capped at 1 (a = 90 degrees without a spread: (r / D)^2 and 1 - sqrt(1 - (r / D)^2), the
latter at most (r / D)^2). A ball whose nearest point lies beyond the max distance changes
nothing; a receiver inside a ball (D <= r) may change by anything (1). Several changed balls
add their bounds. tests/test_change_bound.py checks it against a sphere's exact form factor
over a plane ((r / D)^2 cos(phi): the bound is reached directly below it) and shows that an
exponent of 2.5, or half the bound, fails there.
"""
from __future__ import annotations

import numpy as np

# Receivers per block: a block's (n, k) distances stay a few MB.
BLOCK = 1 << 16


def cone_share(sin_t: np.ndarray, weighting: str, spread_angle: float = 90.0) -> np.ndarray:
    """The largest share of a receiver's weight that a cone of half-angle t (sin_t, (...,),
    in [0, 1]) can hold, under `weighting` inside the spread cone of `spread_angle` degrees."""
    sin_a = np.sin(np.radians(min(max(spread_angle, 1e-6), 90.0)))
    sin_t = np.clip(sin_t, 0.0, 1.0)
    if weighting == "cosine":
        share = sin_t ** 2 / sin_a ** 2
    elif weighting == "uniform":
        cos_a = np.sqrt(max(1.0 - sin_a ** 2, 0.0))
        share = (1.0 - np.sqrt(1.0 - sin_t ** 2)) / (1.0 - cos_a)
    else:
        raise ValueError(f"unknown weighting '{weighting}'")
    return np.minimum(share, 1.0)


def change_bound(points: np.ndarray, spheres: np.ndarray, weighting: str = "cosine",
                 spread_angle: float = 90.0, max_distance: float = 0.0, reach: np.ndarray | None = None
                 ) -> np.ndarray:
    """(n,) float64 in [0, 1]: the most each receiver's AO can change when what lies inside
    spheres changes. points: (n, 3) receivers, world; spheres: (k, 4) centre and radius,
    world (the changed geometry before and after the edit); max_distance: the bake's (0 =
    unlimited); reach: (n,) each point stands for receivers up to this far from it (a face's
    bounding sphere): its spheres grow by it (a ray from a receiver r away that enters a
    sphere passes within radius + r of the point)."""
    points = np.asarray(points, np.float64).reshape(-1, 3)
    reach = np.zeros(len(points)) if reach is None else np.asarray(reach, np.float64)
    spheres = np.asarray(spheres, np.float64).reshape(-1, 4)
    bound = np.zeros(len(points))
    if len(spheres) == 0:
        return bound
    centres = spheres[:, :3]
    for start in range(0, len(points), max(1, BLOCK // len(spheres))):
        block = points[start:start + max(1, BLOCK // len(spheres))]
        distance = np.linalg.norm(block[:, None, :] - centres[None], axis=2)  # (b, k)
        radii = spheres[None, :, 3] + reach[start:start + len(block), None]
        sin_t = np.where(distance > radii, radii / np.maximum(distance, 1e-300), 1.0)
        share = cone_share(sin_t, weighting, spread_angle)
        if max_distance > 0.0:
            share = np.where(distance - radii > max_distance, 0.0, share)
        bound[start:start + len(block)] = np.minimum(share.sum(axis=1), 1.0)
    return bound


def sampled_change_bound(points: np.ndarray, normals: np.ndarray, spheres: np.ndarray, directions: np.ndarray,
                         weighting: str = "cosine", spread_angle: float = 90.0, max_distance: float = 0.0,
                         reach: np.ndarray | None = None, direction_class: np.ndarray | None = None) -> np.ndarray:
    """(n,) float64: the most a bake's own estimate can change at each receiver: the weight
    share of its directions (D, 3) that point into a changed sphere. The estimate is the mean
    over its replicates (core/directions.replicate_sizes: consecutive runs of the directions)
    of sum(V w) / sum(w) over the replicate's directions (estimators.texel_sums), so a
    direction weighs w / (replicates x its replicate's sum of w). The estimate of finitely
    many directions is not bounded by change_bound's share of the whole hemisphere (a
    direction that falls into a small cone moves it by about 1 / D). normals: (n, 3) the
    receivers' shading normals, or (n, m, 3) several each (a face's corners: each direction
    weighs its most over them, each sum its least); reach: as change_bound's; direction_class:
    (D,) the texel class each direction serves (core/bake/interleave.py): a receiver sees its
    class's alone, and the bound is the largest over the classes."""
    from ..directions import replicate_sizes
    from .normalization import hemisphere_weight

    points = np.asarray(points, np.float64).reshape(-1, 3)
    normals = np.asarray(normals, np.float64).reshape(len(points), -1, 3)
    reach = np.zeros(len(points)) if reach is None else np.asarray(reach, np.float64)
    spheres = np.asarray(spheres, np.float64).reshape(-1, 4)
    directions = np.asarray(directions, np.float64).reshape(-1, 3)
    spread_cos = 0.0 if spread_angle >= 90.0 else float(np.cos(np.radians(spread_angle)))
    sizes = np.cumsum([0, *replicate_sizes(len(directions))])
    served = np.zeros(len(directions), np.int64) if direction_class is None else np.asarray(direction_class)
    # each class's directions in each replicate
    runs = [[first + np.flatnonzero(served[first:end] == k) for first, end in zip(sizes[:-1], sizes[1:])]
            for k in np.unique(served)]
    if normals.shape[1] > 1 and (normals == normals[:, :1]).all():
        normals = normals[:, :1]  # flat faces: one normal does for every corner
    bound = np.zeros(len(points))
    rows = max(1, BLOCK * 4 // max(len(directions), 1))
    for start in range(0, len(points), rows):
        p = points[start:start + rows]
        inside = np.zeros((len(p), len(directions)), bool)
        for centre, sphere_radius in zip(spheres[:, :3], spheres[:, 3]):
            radius = sphere_radius + reach[start:start + len(p)]
            to = centre - p
            dist = np.linalg.norm(to, axis=1)
            near = dist > radius
            if max_distance > 0.0:
                near_enough = dist - radius <= max_distance
            else:
                near_enough = np.ones(len(p), bool)
            cos_t = np.sqrt(np.maximum(1.0 - (radius / np.maximum(dist, 1e-300)) ** 2, 0.0))
            aim = (to / np.maximum(dist, 1e-300)[:, None]) @ directions.T  # (b, D)
            inside |= (~near)[:, None] | (near_enough[:, None] & (aim >= cos_t[:, None]))
        # Only receivers with a direction into a sphere weigh their directions (most do not).
        hit = np.flatnonzero(inside.any(axis=1))
        weights = hemisphere_weight(normals[start + hit] @ directions.T, weighting, spread_cos)  # (h, m, D)
        hits = weights.max(axis=1) * inside[hit]
        share = np.zeros(len(hit))
        for replicates in runs:
            of_class = np.zeros(len(hit))
            for own in replicates:
                total = np.maximum(weights[..., own].sum(axis=2).min(axis=1), 1e-300)
                of_class += hits[:, own].sum(axis=1) / (total * len(replicates))
            share = np.maximum(share, of_class)
        bound[start + hit] = np.minimum(share, 1.0)
    return bound


def cell_bound(bound: np.ndarray, cells: np.ndarray, cell_count: int) -> np.ndarray:
    """(cell_count,) the largest receiver bound of each cell (a texel's samples, an element's
    corners); 0 for cells without receivers."""
    out = np.zeros(cell_count)
    np.maximum.at(out, np.asarray(cells, np.int64), bound)
    return out


def face_box_bounds(uvs: np.ndarray, bound: np.ndarray, size: int, grid: int) -> np.ndarray:
    """(size, size) each texel's bound: the largest of the faces (uvs (F, 3, 2), bound (F,))
    whose UV box, grown by a texel, reaches the cell of a grid x grid raster holding it (every
    face that can put a sample point into a texel reaches its cell: a bound for all of them)."""
    grid = min(grid, size)
    lo = np.clip(np.floor((uvs.min(axis=1) - 1.0 / size) * grid), 0, grid - 1).astype(np.int64)
    hi = np.clip(np.floor((uvs.max(axis=1) + 1.0 / size) * grid), 0, grid - 1).astype(np.int64)
    width, height = hi[:, 0] - lo[:, 0] + 1, hi[:, 1] - lo[:, 1] + 1
    count = width * height
    face = np.repeat(np.arange(len(uvs)), count)
    local = np.arange(len(face)) - np.repeat(np.cumsum(count) - count, count)
    cell = (lo[face, 1] + local // width[face]) * grid + lo[face, 0] + local % width[face]
    coarse = np.zeros(grid * grid)
    np.maximum.at(coarse, cell, bound[face])
    rows = np.arange(size) * grid // size
    return coarse.reshape(grid, grid)[rows[:, None], rows[None, :]]


# Pieces a bound is computed over, at most (refined_piece_bounds): a few hundred MB of arrays.
MAX_PIECES = 1 << 21


def _subdivision(level: int) -> np.ndarray:
    """(level^2, 3, 3) barycentric corners of a triangle cut into level^2 like triangles."""
    out = []
    for i in range(level):
        for j in range(level - i):
            a, b, c = (i, j), (i + 1, j), (i, j + 1)
            out.append([a, b, c])
            if i + j < level - 1:
                out.append([(i + 1, j), (i + 1, j + 1), (i, j + 1)])
    ij = np.asarray(out, np.float64) / level  # (level^2, 3, 2): (u, v) weights of corners 1, 2
    return np.concatenate([1.0 - ij.sum(axis=2, keepdims=True), ij], axis=2)


def quartered(*per_corner: np.ndarray) -> list[np.ndarray]:
    """The faces of per_corner arrays (each (F, 3, ...)) each cut into 4 like triangles."""
    bary = _subdivision(2)
    return [np.einsum("pck,fk...->fpc...", bary, array).reshape(-1, *array.shape[1:]) for array in per_corner]


def refined_piece_bounds(world: np.ndarray, uvs: np.ndarray, normals: np.ndarray, bound_of, threshold: float,
                         radius: float) -> tuple[np.ndarray, np.ndarray]:
    """(uvs (P, 3, 2), bound (P,)) of pieces of the faces (world (F, 3, 3), uvs, normals (F,
    3, 3)): each face's bound_of(spheres (k, 4), normals (k, 3, 3)) -> (k,), a bound over
    every point of a piece's sphere, and pieces at or above threshold cut in 4 again until no
    wider than radius (or MAX_PIECES are cut): where an edit cannot reach the threshold, one
    coarse piece answers for a whole face; only near it are pieces fine."""
    from .scene_changes import face_spheres  # the same sphere a state records per face

    done_uvs, done_bounds = [], []
    while len(world):
        spheres = face_spheres(world)
        bound = bound_of(spheres, normals)
        cut = (bound >= threshold) & (spheres[:, 3] > radius)
        if 4 * int(cut.sum()) > MAX_PIECES:
            cut[:] = False
        done_uvs.append(uvs[~cut])
        done_bounds.append(bound[~cut])
        world, uvs, normals = quartered(world[cut], uvs[cut], normals[cut])
    return np.concatenate(done_uvs), np.concatenate(done_bounds)

