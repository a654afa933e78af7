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
                 spread_angle: float = 90.0, max_distance: float = 0.0) -> np.ndarray:
    """(n,) float64 in [0, 1]: the most each receiver's AO can change when what lies inside
    spheres changes. points: (n, 3) receivers, world; spheres: (k, 4) centre and radius,
    world (the changed geometry before and after the edit); max_distance: the bake's (0 =
    unlimited)."""
    points = np.asarray(points, np.float64).reshape(-1, 3)
    spheres = np.asarray(spheres, np.float64).reshape(-1, 4)
    bound = np.zeros(len(points))
    if len(spheres) == 0:
        return bound
    centres, radii = spheres[:, :3], spheres[:, 3]
    for start in range(0, len(points), max(1, BLOCK // len(spheres))):
        block = points[start:start + max(1, BLOCK // len(spheres))]
        distance = np.linalg.norm(block[:, None, :] - centres[None], axis=2)  # (b, k)
        sin_t = np.where(distance > radii, radii / np.maximum(distance, 1e-300), 1.0)
        share = cone_share(sin_t, weighting, spread_angle)
        if max_distance > 0.0:
            share = np.where(distance - radii > max_distance, 0.0, share)
        bound[start:start + len(block)] = np.minimum(share.sum(axis=1), 1.0)
    return bound


def sampled_change_bound(points: np.ndarray, normals: np.ndarray, spheres: np.ndarray, directions: np.ndarray,
                         weighting: str = "cosine", spread_angle: float = 90.0, max_distance: float = 0.0
                         ) -> np.ndarray:
    """(n,) float64: the most a bake's own estimate (sum of V w over its directions / sum of w)
    can change at each receiver: the weight share of its directions (D, 3) that point into a
    changed sphere. The estimate of finitely many directions is not bounded by change_bound's
    share of the whole hemisphere (a direction that falls into a small cone moves it by about
    1 / D); kept texels are held to both. normals: (n, 3) the receivers' shading normals."""
    from .normalization import hemisphere_weight

    points = np.asarray(points, np.float64).reshape(-1, 3)
    spheres = np.asarray(spheres, np.float64).reshape(-1, 4)
    directions = np.asarray(directions, np.float64).reshape(-1, 3)
    spread_cos = 0.0 if spread_angle >= 90.0 else float(np.cos(np.radians(spread_angle)))
    bound = np.zeros(len(points))
    rows = max(1, BLOCK * 4 // max(len(directions), 1))
    for start in range(0, len(points), rows):
        p, n = points[start:start + rows], normals[start:start + rows]
        weight = hemisphere_weight(n @ directions.T, weighting, spread_cos)  # (b, D)
        total = np.maximum(weight.sum(axis=1), 1e-300)
        inside = np.zeros(weight.shape, bool)
        for centre, radius in zip(spheres[:, :3], spheres[:, 3]):
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
        bound[start:start + len(p)] = np.minimum((weight * inside).sum(axis=1) / total, 1.0)
    return bound


def cell_bound(bound: np.ndarray, cells: np.ndarray, cell_count: int) -> np.ndarray:
    """(cell_count,) the largest receiver bound of each cell (a texel's samples, an element's
    corners); 0 for cells without receivers."""
    out = np.zeros(cell_count)
    np.maximum.at(out, np.asarray(cells, np.int64), bound)
    return out
