# SPDX-License-Identifier: GPL-3.0-or-later
"""Contacts: where two surfaces meet, nearly touch or pass through each other, closer than a
depth map can tell apart (pure numpy).

Why: a shadow-map test allows a receiver some depth slack (gpu/gather_shaders.py,
DEPTH_BIAS_PIXELS and the plane's slope over the pixel it reads), so an occluder nearer than
about a light-view pixel along the ray is not seen. A prop resting on a floor is just that: the
floor under a torus lies 0.0005 below the texels of its lowest faces where a pixel is 0.04
wide, and the contact baked 0.98 where the exact AO is 0.01. The receivers such an occluder
faces are found here; a baker that declares it (abilities.traces_contacts) traces them exactly
(hao_addon/contact_repair.py).

A receiver p (geometric normal n) is in contact with a face g (normal m) when
- the nearest point q of g lies within `reach` of p,
- each lies in front of the other's plane: (q - p) . n >= 0 and (p - q) . m >= 0 (within a
  hair): a convex crease, the far side of a thin sheet or a face behind p are not contacts,
- and g turns towards p or across it: n . m < CONTACT_COS. The receiver's own smooth surface
  (neighbours in a smooth concave region have nearly its normal) is what the depth slack is
  for, and it keeps those; a floor under a prop (opposite normals), a wall beside it or a
  concave crease (perpendicular) are contacts.
"""
from __future__ import annotations

import numpy as np

# Faces whose normals meet at a larger angle than this (60 degrees) can be contacts.
CONTACT_COS = 0.5
# A face is tested against a receiver's grid cell where its box, grown by the reach, covers at
# most this many cells; larger ones (a floor of two triangles) are tested against every point.
MAX_CELLS_PER_FACE = 512
# The grid's cells are at least the reach, the items' median box and their extent over this.
GRID_DIVISIONS = 256
# "In front" allows this share of the reach behind a plane (float32 corners on one plane).
FRONT_SLACK = 1e-3


def closest_points(p: np.ndarray, tri: np.ndarray) -> np.ndarray:
    """(n, 3) the point of each triangle tri (n, 3, 3) nearest to p (n, 3) (Ericson's
    regions, vectorized)."""
    a, b, c = tri[:, 0], tri[:, 1], tri[:, 2]
    ab, ac, ap = b - a, c - a, p - a
    d1, d2 = _dot(ab, ap), _dot(ac, ap)
    bp, cp = p - b, p - c
    d3, d4 = _dot(ab, bp), _dot(ac, bp)
    d5, d6 = _dot(ab, cp), _dot(ac, cp)
    va = d3 * d6 - d5 * d4
    vb = d5 * d2 - d1 * d6
    vc = d1 * d4 - d3 * d2
    with np.errstate(divide="ignore", invalid="ignore"):
        denom = va + vb + vc
        v = np.where(denom != 0.0, vb / denom, 0.0)
        w = np.where(denom != 0.0, vc / denom, 0.0)
        out = a + ab * v[:, None] + ac * w[:, None]  # inside the face
        # Edges (where the point projects outside across one), then corners.
        t_ab = np.clip(d1 / np.where(d1 - d3 != 0.0, d1 - d3, 1.0), 0.0, 1.0)
        t_ac = np.clip(d2 / np.where(d2 - d6 != 0.0, d2 - d6, 1.0), 0.0, 1.0)
        t_bc = np.clip((d4 - d3) / np.where((d4 - d3) + (d5 - d6) != 0.0, (d4 - d3) + (d5 - d6), 1.0), 0.0, 1.0)
    on_ab = a + ab * t_ab[:, None]
    on_ac = a + ac * t_ac[:, None]
    on_bc = b + (c - b) * t_bc[:, None]
    outside = (va < 0.0) | (vb < 0.0) | (vc < 0.0) | ~np.isfinite(v) | ~np.isfinite(w)
    if outside.any():
        candidates = np.stack([on_ab, on_ac, on_bc])[:, outside]
        dist = ((candidates - p[outside][None]) ** 2).sum(-1)
        out[outside] = candidates[np.argmin(dist, axis=0), np.arange(int(outside.sum()))]
    return out


def _dot(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    return np.einsum("ij,ij->i", x, y)


def face_normals(tri: np.ndarray) -> np.ndarray:
    """(n, 3) unit normals of (n, 3, 3) triangles (0 for degenerate ones)."""
    n = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    length = np.linalg.norm(n, axis=1, keepdims=True)
    return np.divide(n, length, out=np.zeros_like(n), where=length > 0.0)


def _pairs(points_lo: np.ndarray, points_hi: np.ndarray, faces_lo: np.ndarray, faces_hi: np.ndarray,
           reach: float) -> tuple[np.ndarray, np.ndarray]:
    """(i, g) index pairs whose boxes (points' [lo, hi], faces' grown by reach) overlap:
    items i (n,) against faces g (m,), through a uniform grid over the items."""
    if len(points_lo) == 0 or len(faces_lo) == 0:
        return np.zeros(0, np.int64), np.zeros(0, np.int64)
    origin = points_lo.min(0)
    extent = float((points_hi.max(0) - origin).max())
    # An item's box and a face's cover a few cells each (points: about a face's half).
    typical = max(float(np.median((points_hi - points_lo).max(axis=1))),
                  0.5 * float(np.median((faces_hi - faces_lo).max(axis=1))))
    cell = max(reach, extent / GRID_DIVISIONS, typical, 1e-12)
    dims = np.maximum(np.floor((points_hi.max(0) - origin) / cell).astype(np.int64) + 1, 1)
    lo_cell = np.clip(np.floor((points_lo - origin) / cell).astype(np.int64), 0, dims - 1)
    hi_cell = np.clip(np.floor((points_hi - origin) / cell).astype(np.int64), 0, dims - 1)
    f_lo = np.floor((faces_lo - reach - origin) / cell).astype(np.int64)
    f_hi = np.floor((faces_hi + reach - origin) / cell).astype(np.int64)
    f_lo, f_hi = np.maximum(f_lo, 0), np.minimum(f_hi, dims - 1)
    present = (f_hi >= f_lo).all(axis=1)
    spans = np.where(present[:, None], f_hi - f_lo + 1, 0)
    cells_per_face = spans.prod(axis=1)
    # Items are keyed by every cell their box covers (a point: one).
    item_spans = hi_cell - lo_cell + 1
    item_counts = item_spans.prod(axis=1)
    item_index = np.repeat(np.arange(len(points_lo)), item_counts)
    item_keys = _cell_keys(np.repeat(lo_cell, item_counts, axis=0), np.repeat(item_spans, item_counts, axis=0),
                           _ranks(item_counts), dims)
    order = np.argsort(item_keys, kind="stable")
    item_keys, item_index = item_keys[order], item_index[order]
    small = present & (cells_per_face <= MAX_CELLS_PER_FACE)
    idx = np.flatnonzero(small)
    counts = cells_per_face[idx]
    face_of = np.repeat(idx, counts)
    keys = _cell_keys(np.repeat(f_lo[idx], counts, axis=0), np.repeat(spans[idx], counts, axis=0),
                      _ranks(counts), dims)
    start, end = np.searchsorted(item_keys, keys, "left"), np.searchsorted(item_keys, keys, "right")
    hits = end - start
    pair_g = np.repeat(face_of, hits)
    pair_i = item_index[np.repeat(start, hits) + _ranks(hits)]
    big = np.flatnonzero(present & ~small)
    extra_i, extra_g = [], []
    for g in big:  # few: every item's box against the face's grown box
        near = ((points_hi >= faces_lo[g] - reach) & (points_lo <= faces_hi[g] + reach)).all(axis=1)
        extra_i.append(np.flatnonzero(near))
        extra_g.append(np.full(int(near.sum()), g))
    pair_i = np.concatenate([pair_i, *extra_i]).astype(np.int64)
    pair_g = np.concatenate([pair_g, *extra_g]).astype(np.int64)
    if len(pair_i) == 0:
        return pair_i, pair_g
    if not (item_counts > 1).any():  # points: one cell each, so every pair is listed once
        return pair_i, pair_g
    unique = np.unique(pair_i * len(faces_lo) + pair_g)  # an item's box over several cells meets a face once
    return unique // len(faces_lo), unique % len(faces_lo)


def _ranks(counts: np.ndarray) -> np.ndarray:
    """0 .. count - 1 for each count, concatenated."""
    total = int(counts.sum())
    return np.arange(total) - np.repeat(np.cumsum(counts) - counts, counts)


def _cell_keys(lo: np.ndarray, spans: np.ndarray, rank: np.ndarray, dims: np.ndarray) -> np.ndarray:
    """Flat keys of the rank-th cell of each box starting at lo (k, 3) with spans (k, 3)."""
    x = lo[:, 0] + rank % spans[:, 0]
    y = lo[:, 1] + (rank // spans[:, 0]) % spans[:, 1]
    z = lo[:, 2] + rank // (spans[:, 0] * spans[:, 1])
    return (z * dims[1] + y) * dims[0] + x


def contact_faces(target: np.ndarray, drawn: np.ndarray, reach: float) -> tuple[np.ndarray, np.ndarray]:
    """(faces, partners): (k,) sorted indices of target triangles (Ft, 3, 3) that a drawn
    triangle (F, 3, 3) can be in contact with (module docstring) somewhere, the faces whose
    receivers need the exact test, and (j,) sorted indices of those drawn triangles."""
    target, drawn = np.asarray(target, np.float64), np.asarray(drawn, np.float64)
    f, g = _pairs(target.min(1), target.max(1), drawn.min(1), drawn.max(1), reach)
    if len(f) == 0:
        return np.zeros(0, np.int64), np.zeros(0, np.int64)
    n, m = face_normals(target), face_normals(drawn)
    keep = _dot(n[f], m[g]) < CONTACT_COS
    f, g = f[keep], g[keep]
    slack = FRONT_SLACK * reach
    # Some corner of each lies in front of the other's plane (necessary for a contact), or the
    # two lie on one plane facing each other (a box resting on a floor). A convex crease's
    # faces share their corners on the crease and are otherwise behind each other: no contact.
    g_height = np.einsum("gkd,gd->gk", drawn[g] - target[f, :1], n[f])
    f_height = np.einsum("gkd,gd->gk", target[f] - drawn[g, :1], m[g])
    facing = (g_height > slack).any(axis=1) & (f_height > slack).any(axis=1)
    touching = (_dot(n[f], m[g]) < -1.0 + 1e-6) & (np.abs(g_height) <= slack).all(axis=1)
    return np.unique(f[facing | touching]), np.unique(g[facing | touching])


def contact_points(points: np.ndarray, normals: np.ndarray, drawn: np.ndarray, reach: float) -> np.ndarray:
    """(n,) bool: which points (n, 3) with unit geometric normals (n, 3) are in contact with a
    triangle of drawn (F, 3, 3) (module docstring)."""
    points, drawn = np.asarray(points, np.float64), np.asarray(drawn, np.float64)
    found = np.zeros(len(points), bool)
    i, g = _pairs(points, points, drawn.min(1), drawn.max(1), reach)
    if len(i) == 0:
        return found
    m = face_normals(drawn)
    keep = _dot(normals[i], m[g]) < CONTACT_COS
    i, g = i[keep], g[keep]
    q = closest_points(points[i], drawn[g])
    d = q - points[i]
    slack = FRONT_SLACK * reach
    near = ((d ** 2).sum(1) < reach * reach) & (_dot(d, normals[i]) >= -slack) & (_dot(-d, m[g]) >= -slack)
    found[i[near]] = True
    return found
