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
    if (item_counts > 1).any():  # an item's box over several cells meets a face once
        unique = np.unique(pair_i * len(faces_lo) + pair_g)
        pair_i, pair_g = unique // len(faces_lo), unique % len(faces_lo)
    # Sharing a cell is not overlapping: the boxes themselves (a floor's cells are as tall as
    # the props' faces, and half a torus shared them).
    overlap = ((points_hi[pair_i] >= faces_lo[pair_g] - reach) & (points_lo[pair_i] <= faces_hi[pair_g] + reach)).all(1)
    return pair_i[overlap], pair_g[overlap]


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


def contact_pairs(target: np.ndarray, drawn: np.ndarray, reach: float) -> tuple[np.ndarray, np.ndarray]:
    """(f, g): the (target face, drawn face) index pairs of contact_faces, one per pair."""
    target, drawn = np.asarray(target, np.float64), np.asarray(drawn, np.float64)
    f, g = _pairs(target.min(1), target.max(1), drawn.min(1), drawn.max(1), reach)
    if len(f) == 0:
        return f, g
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
    return f[facing | touching], g[facing | touching]


def _uv_windows(tri: np.ndarray, tuv: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(lo (k, 2), hi (k, 2)): the UV box of each box [lo, hi] (k, 3)'s corners projected onto
    its triangle's plane (tri (k, 3, 3), tuv (k, 3, 2)), within the triangle's own UV box
    (the whole of it for a degenerate triangle)."""
    corners = np.stack([np.where([(k >> a) & 1 for a in range(3)], hi, lo) for k in range(8)], axis=1)  # (k, 8, 3)
    edges = np.stack([tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]], axis=2)  # (k, 3, 2)
    gram = np.einsum("kdi,kdj->kij", edges, edges)
    ok = np.abs(np.linalg.det(gram)) > 1e-30
    gram[~ok] = np.eye(2)
    lam = np.einsum("kij,kdj,kcd->kci", np.linalg.inv(gram), edges, corners - tri[:, None, 0])  # (k, 8, 2)
    corner_uv = tuv[:, None, 0] + np.einsum("kci,kid->kcd", lam, np.stack([tuv[:, 1] - tuv[:, 0],
                                                                           tuv[:, 2] - tuv[:, 0]], axis=1))
    win_lo = np.where(ok[:, None], np.maximum(corner_uv.min(axis=1), tuv.min(axis=1)), tuv.min(axis=1))
    win_hi = np.where(ok[:, None], np.minimum(corner_uv.max(axis=1), tuv.max(axis=1)), tuv.max(axis=1))
    return win_lo, win_hi


def window_samples(positions: np.ndarray, uvs: np.ndarray, face: np.ndarray, lo: np.ndarray, hi: np.ndarray,
                   size: int, grid: int = 1) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(texel (m,) flat y * size + x, face (m,), bary (m, 3)) of the sample points (grid x grid
    per texel, as receivers.texel_sample_points) of target faces that lie in the UV window of
    a box: face (k,) indices into positions (Ft, 3, 3) and uvs (Ft, 3, 2), each with the box
    [lo, hi] (k, 3) it may come near. The window is the UV bounding box of the box's corners
    projected onto the face's plane (the face's part inside the box lies within it), so only
    what is near is rasterized: a floor of two triangles under a prop is a few small windows,
    where its whole raster (a million texels at 1024^2) took 0.96 s. Where a face's windows
    add up to more than its own UV box, that box is taken instead, once."""
    from .uv_raster import inset_barycentrics
    n = size * grid
    if len(face) == 0:
        return np.zeros(0, np.int64), np.zeros(0, np.int64), np.zeros((0, 3))
    tuv = np.asarray(uvs, np.float64)[face]
    win_lo, win_hi = _uv_windows(np.asarray(positions, np.float64)[face], tuv, lo, hi)
    i_lo = np.clip(np.ceil(win_lo * n - 0.5 - 1e-9), 0, n - 1).astype(np.int64)
    i_hi = np.clip(np.floor(win_hi * n - 0.5 + 1e-9), 0, n - 1).astype(np.int64)
    spans = np.maximum(i_hi - i_lo + 1, 0)
    spans[(win_hi < win_lo).any(axis=1)] = 0
    area = spans.prod(axis=1)
    # A face whose windows add up to more than its own box: its box, once.
    box_lo = np.clip(np.ceil(tuv.min(axis=1) * n - 0.5 - 1e-9), 0, n - 1).astype(np.int64)
    box_hi = np.clip(np.floor(tuv.max(axis=1) * n - 0.5 + 1e-9), 0, n - 1).astype(np.int64)
    box_area = np.maximum(box_hi - box_lo + 1, 0).prod(axis=1)
    total = np.bincount(face, weights=area, minlength=len(positions))
    whole = total[face] > box_area
    if whole.any():
        _faces, index = np.unique(face[whole], return_index=True)
        keep_whole = np.flatnonzero(whole)[index]
        i_lo[keep_whole], spans[keep_whole] = box_lo[keep_whole], np.maximum(box_hi - box_lo + 1, 0)[keep_whole]
        drop = np.setdiff1d(np.flatnonzero(whole), keep_whole)
        spans[drop] = 0
        area = spans.prod(axis=1)
    pair = np.repeat(np.arange(len(face)), area)
    rank = _ranks(area)
    x = i_lo[pair, 0] + rank % np.maximum(spans[pair, 0], 1)
    y = i_lo[pair, 1] + rank // np.maximum(spans[pair, 0], 1)
    point = np.stack([(x + 0.5) / n, (y + 0.5) / n], axis=1)
    a, b, c = tuv[pair, 0], tuv[pair, 1], tuv[pair, 2]
    det = (b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (c[:, 0] - a[:, 0]) * (b[:, 1] - a[:, 1])
    with np.errstate(divide="ignore", invalid="ignore"):
        w1 = ((point[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (c[:, 0] - a[:, 0]) * (point[:, 1] - a[:, 1])) / det
        w2 = ((b[:, 0] - a[:, 0]) * (point[:, 1] - a[:, 1]) - (point[:, 0] - a[:, 0]) * (b[:, 1] - a[:, 1])) / det
    bary = np.stack([1.0 - w1 - w2, w1, w2], axis=1)
    inside = np.isfinite(bary).all(axis=1) & (bary >= -1e-9).all(axis=1)
    key = (y * n + x)[inside] * len(positions) + face[pair][inside]
    _unique, at = np.unique(key, return_index=True)
    sample, faces = (y * n + x)[inside][at], face[pair][inside][at]
    texel = (sample // n // grid) * size + (sample % n) // grid
    return texel.astype(np.int64), faces.astype(np.int64), inset_barycentrics(bary[inside][at])


def contact_faces(target: np.ndarray, drawn: np.ndarray, reach: float) -> tuple[np.ndarray, np.ndarray]:
    """(faces, partners): (k,) sorted indices of target triangles (Ft, 3, 3) that a drawn
    triangle (F, 3, 3) can be in contact with (module docstring) somewhere, the faces whose
    receivers need the exact test, and (j,) sorted indices of those drawn triangles."""
    f, g = contact_pairs(target, drawn, reach)
    return np.unique(f), np.unique(g)


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
