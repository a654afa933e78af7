# SPDX-License-Identifier: GPL-3.0-or-later
"""Sphere proxies of a mesh: area-weighted Lloyd clustering (k-means) of the rest-pose
vertices, and per-frame spheres from deformed positions (pure numpy).

The paper (Shanmugam & Arikan, section 5) clusters the rest pose with Lloyd's algorithm and
"repositions the spheres based on the new vertex positions" every frame. Here a sphere is
the area-weighted centroid of its cluster's vertices and its radius the area-weighted RMS
distance to it: the sphere of the same second moment, neither the cluster's enclosing
sphere (which over-occludes) nor a point."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np


class ProxyError(ValueError):
    """Input that cannot give sphere proxies; the message says why."""


@dataclass
class Clustering:
    labels: np.ndarray   # (V,) int32 cluster of each vertex
    energies: list       # area-weighted sum of squared distances after each iteration
    iterations: int
    converged: bool


def vertex_areas(vertices: np.ndarray, triangles: np.ndarray) -> np.ndarray:
    """(V,) one third of the area of the triangles around each vertex."""
    v = np.asarray(vertices, np.float64)
    t = np.asarray(triangles, np.int64)
    area = 0.5 * np.linalg.norm(np.cross(v[t[:, 1]] - v[t[:, 0]], v[t[:, 2]] - v[t[:, 0]]), axis=1)
    return np.bincount(t.ravel(), weights=np.repeat(area / 3.0, 3), minlength=len(v))


def _assign(points: np.ndarray, centres: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Nearest centre and squared distance for each point (chunked: K x V can be large)."""
    labels = np.empty(len(points), np.int64)
    d2 = np.empty(len(points))
    cc = (centres * centres).sum(1)
    for start in range(0, len(points), 65536):
        p = points[start:start + 65536]
        dist = cc[None, :] - 2.0 * p @ centres.T + (p * p).sum(1)[:, None]
        labels[start:start + 65536] = np.argmin(dist, axis=1)
        d2[start:start + 65536] = np.maximum(dist[np.arange(len(p)), labels[start:start + 65536]], 0.0)
    return labels, d2


def lloyd_clusters(vertices: np.ndarray, weights: np.ndarray, k: int, seed: int = 0, tolerance: float = 1e-6,
                   max_iterations: int = 100) -> Clustering:
    """Area-weighted k-means of (V, 3) vertices into k clusters.

    Seeding: weighted k-means++ from a seeded generator (deterministic). Stops when the energy
    drops by less than `tolerance` (relative) or after `max_iterations`. The energy never
    increases: each assignment and each centroid update can only lower it."""
    points = np.asarray(vertices, np.float64)
    w = np.asarray(weights, np.float64)
    n = len(points)
    if not 1 <= k <= n:
        raise ProxyError(f"cannot make {k} sphere proxies from {n} vertices: choose 1..{n}")
    if not np.isfinite(points).all():
        raise ProxyError("the mesh has NaN or infinite vertex positions")
    if not (w > 0).any():
        raise ProxyError("the mesh has no surface area (all faces degenerate)")
    w = np.maximum(w, 1e-12 * w.max())  # isolated vertices still belong somewhere
    rng = np.random.default_rng(seed)
    centres = np.empty((k, 3))
    centres[0] = points[rng.choice(n, p=w / w.sum())]
    d2 = ((points - centres[0]) ** 2).sum(1)
    for i in range(1, k):
        p = w * d2
        idx = rng.choice(n, p=p / p.sum()) if p.sum() > 0 else int(rng.integers(n))
        centres[i] = points[idx]
        d2 = np.minimum(d2, ((points - centres[i]) ** 2).sum(1))
    energies = []
    converged = False
    labels = None
    for it in range(max_iterations):  # noqa: B007 - the count it reached is returned
        labels, d2 = _assign(points, centres)
        energies.append(float((w * d2).sum()))
        mass = np.bincount(labels, weights=w, minlength=k)
        for axis in range(3):
            sums = np.bincount(labels, weights=w * points[:, axis], minlength=k)
            centres[:, axis] = np.where(mass > 0, sums / np.where(mass > 0, mass, 1.0), centres[:, axis])
        if len(energies) > 1 and energies[-2] - energies[-1] <= tolerance * max(energies[-2], 1e-300):
            converged = True
            break
    labels, d2 = _assign(points, centres)
    energies.append(float((w * d2).sum()))
    return Clustering(labels.astype(np.int32), energies, it + 1, converged)


def sphere_proxies(positions: np.ndarray, labels: np.ndarray, weights: np.ndarray, k: int) -> tuple[np.ndarray, np.ndarray]:
    """Centres (k, 3) and radii (k,) of the clusters at (V, 3) (deformed) positions:
    area-weighted centroid and RMS distance.

    Four weighted bincounts (w x, w y, w z, w |x|^2) and no gather of centres per vertex
    (fancy indexing of 100k rows costs as much as the whole update here): the RMS distance
    is then sqrt(E|x|^2 - |c|^2). That difference cancels when a cluster is far from the
    origin relative to its size, so callers pass object-space positions (a character is
    modelled around its origin; float64 keeps about 1e-8 relative precision: tested at
    1,000 units for 5-cm spheres)."""
    p = np.asarray(positions, np.float64)
    if len(p) != len(labels):
        raise ProxyError(f"the mesh now has {len(p)} vertices but its sphere proxies were made for {len(labels)} "
                         "(a modifier changed the topology): sync the sphere proxies again")
    w = np.asarray(weights, np.float64)
    mass = np.bincount(labels, weights=w, minlength=k)
    safe = np.where(mass > 0, mass, 1.0)
    centres = np.stack([np.bincount(labels, weights=p[:, a] * w, minlength=k) for a in range(3)], 1) / safe[:, None]
    second = np.bincount(labels, weights=np.einsum("ij,ij->i", p, p) * w, minlength=k) / safe
    radii = np.sqrt(np.maximum(second - (centres * centres).sum(1), 0.0))
    return centres, radii


def check_radii(radii: np.ndarray) -> None:
    """ProxyError when a sphere has zero radius (a cluster of one vertex, or of coincident
    vertices): such a proxy occludes nothing, so the clustering asked for too many spheres."""
    zero = np.flatnonzero(~(np.asarray(radii) > 0.0))
    if len(zero):
        raise ProxyError(f"{len(zero)} of {len(radii)} sphere proxies have zero radius (clusters of a single point, "
                         f"first: {int(zero[0])}): use fewer spheres")
