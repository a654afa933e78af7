# SPDX-License-Identifier: GPL-3.0-or-later
"""CPU rasterization of UV triangles: which surface point each texel centre maps to.

Used by the references and the error metrics, independently of the GPU passes.
"""
from __future__ import annotations

import numpy as np


# A texel's sample point lies at least this barycentric share inside its face: a centre on an
# edge (or, on the GPU, snapped up to 1/256 texel past it) otherwise sits on the crease, where
# rounding puts it behind a neighbouring face at a concave angle and every ray from it leaves
# through that face's back (fandisk at 128^2: five texels read 0.000 instead of 0.4-0.5 in the
# exact truth). 1/1024 of a face's height is far below a texel and above float rounding.
SAMPLE_INSET = 1.0 / 1024.0


def inset_barycentrics(bary: np.ndarray) -> np.ndarray:
    """(..., 3) barycentric coordinates moved SAMPLE_INSET inside their triangle (the GLSL twin:
    bake_texel_list.frag's inset_bary)."""
    b = np.maximum(bary, SAMPLE_INSET)
    return b / b.sum(axis=-1, keepdims=True)


# Candidate texels (faces' bounding boxes) tested at once, at most: a block's arrays stay
# about 200 MB however large the map.
CANDIDATE_BLOCK = 1 << 22


def texel_surface_samples(uvs: np.ndarray, size: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """For every texel whose centre lies in a UV triangle, that triangle and the barycentric
    coordinates of the centre.

    uvs: (F, 3, 2) UV corners in [0, 1]. Returns (face_index (size, size) int64, -1 where
    uncovered; bary (size, size, 3) float64, inset_barycentrics' where covered; hits (size, size) int32: how many triangles
    contain the centre (> 1 where UV islands overlap)). Row y holds v = (y + 0.5) / size.
    Where triangles overlap, the first (lowest index) holds the texel. Faces are tested in
    blocks of whole bounding boxes (numpy, no loop per face).
    """
    face = np.full(size * size, -1, dtype=np.int64)
    bary = np.zeros((size * size, 3), dtype=np.float64)
    hits = np.zeros(size * size, dtype=np.int32)
    p = uvs * size - 0.5  # texel-centre coordinates: centre of texel i is at i
    lo = np.clip(np.ceil(p.min(axis=1) - 1e-9), 0, size - 1).astype(np.int64)
    hi = np.clip(np.floor(p.max(axis=1) + 1e-9), 0, size - 1).astype(np.int64)
    a, b, c = p[:, 0], p[:, 1], p[:, 2]
    det = (b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (c[:, 0] - a[:, 0]) * (b[:, 1] - a[:, 1])
    width, height = hi[:, 0] - lo[:, 0] + 1, hi[:, 1] - lo[:, 1] + 1
    # Zero-area UV triangles cover no texel centre; empty boxes (outside the tile) none either.
    count = np.where((width > 0) & (height > 0) & (np.abs(det) >= 1e-12), width * height, 0)
    ends = np.cumsum(count)
    first = 0
    while first < len(uvs):
        last = int(np.searchsorted(ends, (ends[first - 1] if first else 0) + CANDIDATE_BLOCK, side="right"))
        last = max(last, first + 1)
        _raster_block(np.arange(first, min(last, len(uvs))), count, lo, width, a, b, c, det, size, face, bary, hits)
        first = last
    covered = face >= 0
    bary[covered] = inset_barycentrics(bary[covered])
    return face.reshape(size, size), bary.reshape(size, size, 3), hits.reshape(size, size)


def _raster_block(faces, count, lo, width, a, b, c, det, size, face, bary, hits) -> None:
    """Test every texel centre of faces' bounding boxes; fill face and bary (flat) where no
    earlier face holds the texel, count strict hits."""
    n = count[faces]
    f = np.repeat(faces, n)
    if len(f) == 0:
        return
    local = np.arange(len(f)) - np.repeat(np.cumsum(n) - n, n)
    xs = lo[f, 0] + local % width[f]
    ys = lo[f, 1] + local // width[f]
    af, bf, cf, d = a[f], b[f], c[f], det[f]
    w1 = ((xs - af[:, 0]) * (cf[:, 1] - af[:, 1]) - (cf[:, 0] - af[:, 0]) * (ys - af[:, 1])) / d
    w2 = ((bf[:, 0] - af[:, 0]) * (ys - af[:, 1]) - (xs - af[:, 0]) * (bf[:, 1] - af[:, 1])) / d
    w0 = 1.0 - w1 - w2
    texel = ys * size + xs
    strict = (w0 > 1e-7) & (w1 > 1e-7) & (w2 > 1e-7)
    np.add.at(hits, texel[strict], 1)
    inside = np.flatnonzero((w0 >= -1e-9) & (w1 >= -1e-9) & (w2 >= -1e-9))
    # The first face (candidates are in face order) of each texel no earlier block filled.
    cells, at = np.unique(texel[inside], return_index=True)
    take = inside[at][face[cells] < 0]
    face[texel[take]] = f[take]
    bary[texel[take]] = np.stack([w0[take], w1[take], w2[take]], axis=1)


def interior_mask(face: np.ndarray, hits: np.ndarray, rings: int = 2) -> np.ndarray:
    """Texels whose whole (2 rings + 1)^2 neighbourhood is covered, never twice: away from
    chart borders and overlaps, where a texel-area bake and a point reference agree."""
    ok = (face >= 0) & (hits <= 1)
    out = ok.copy()
    h, w = ok.shape
    for dy in range(-rings, rings + 1):
        for dx in range(-rings, rings + 1):
            shifted = np.zeros_like(ok)
            ys = slice(max(dy, 0), h + min(dy, 0))
            yd = slice(max(-dy, 0), h + min(-dy, 0))
            xs = slice(max(dx, 0), w + min(dx, 0))
            xd = slice(max(-dx, 0), w + min(-dx, 0))
            shifted[yd, xd] = ok[ys, xs]
            out &= shifted
    return out


# Faces tested against the sampled texels at once (texel_area_points): bounds the (face, texel)
# pairs held in memory, whatever the map's size.
AREA_FACE_BLOCK = 4096


def area_strata(points: int) -> tuple[np.ndarray, np.ndarray]:
    """Cells of the unit texel, one per point: a side x side grid when `points` is a square,
    else `points` vertical strips. Returns (origin (points, 2), extent (2,)) in texel units."""
    side = int(round(np.sqrt(points)))
    cols, rows = (side, side) if side * side == points else (points, 1)
    k = np.arange(points)
    extent = np.array([1.0 / cols, 1.0 / rows])
    return np.stack([k % cols, k // cols], axis=1) * extent, extent


def texel_area_points(uvs: np.ndarray, size: int, cells: np.ndarray, seed: int, points: int = 1, tries: int = 8
                      ) -> tuple[np.ndarray, np.ndarray]:
    """`points` points per texel of `cells`, together uniform over the part of the texel that UV
    triangles cover (a texel-area average's random sample: the scatter's floor check,
    hao_addon/floor_check.py): `tries` points for each, the first one inside a triangle kept
    (the first triangle in order, as texel_surface_samples picks). Each point's first try is
    uniform in a cell of its own (area_strata), so a wholly covered texel's points are
    stratified and their mean varies less; later tries are uniform over the texel, so where a
    cell is only partly covered the points' mixture stays uniform over the covered part.

    uvs: (F, 3, 2) UV corners in [0, 1]; cells: (n,) distinct flat texel indices y * size + x.
    Returns (face (n, points) int64, -1 where no try landed on a triangle; bary (n, points, 3)
    float64, inset as inset_barycentrics)."""
    cells = np.asarray(cells, np.int64)
    n, m = len(cells), points * tries
    rng = np.random.default_rng([seed, size, n, points])
    local = rng.random((n, points, tries, 2))
    origin, extent = area_strata(points)
    local[:, :, 0] = origin + extent * local[:, :, 0]  # each point's first try in its own cell
    tries_uv = (np.stack([cells % size, cells // size], axis=1)[:, None, :] + local.reshape(n, m, 2)) / size
    best = np.full((n, m), np.iinfo(np.int64).max)  # the first triangle containing each try
    bary = np.zeros((n, m, 3))
    slot = np.full(size * size, -1, np.int64)
    slot[cells] = np.arange(n)
    uvs = np.asarray(uvs, np.float64)
    p = uvs * size
    lo = np.clip(np.floor(p.min(axis=1)), 0, size - 1).astype(np.int64)
    hi = np.clip(np.floor(p.max(axis=1)), 0, size - 1).astype(np.int64)
    for start in range(0, len(uvs), AREA_FACE_BLOCK):
        faces = np.arange(start, min(start + AREA_FACE_BLOCK, len(uvs)))
        area = (hi[faces, 0] - lo[faces, 0] + 1) * (hi[faces, 1] - lo[faces, 1] + 1)
        face = np.repeat(faces, area)  # every (face, texel of its bounding box) pair
        k = np.arange(len(face)) - np.repeat(np.cumsum(area) - area, area)
        width = hi[face, 0] - lo[face, 0] + 1
        cell = (lo[face, 1] + k // width) * size + lo[face, 0] + k % width
        sampled = slot[cell] >= 0
        face, row = face[sampled], slot[cell[sampled]]
        _pair_barycentrics(uvs, face, row, tries_uv, best, bary)
    landed = (best < np.iinfo(np.int64).max).reshape(n, points, tries)
    first = landed.argmax(axis=2)[..., None]  # each point's first try that landed
    found = np.take_along_axis(landed, first, axis=2)[..., 0]
    face = np.where(found, np.take_along_axis(best.reshape(n, points, tries), first, axis=2)[..., 0], -1)
    out = np.take_along_axis(bary.reshape(n, points, tries, 3), first[..., None], axis=2)[:, :, 0]
    out[found] = inset_barycentrics(out[found])
    return face, out


def _pair_barycentrics(uvs: np.ndarray, face: np.ndarray, row: np.ndarray, tries_uv: np.ndarray,
                       best: np.ndarray, bary: np.ndarray) -> None:
    """For (face, row) pairs, test row's tries (tries_uv[row]: (pairs, m, 2)) against the
    face's UV triangle; where a try lies inside a face lower than best's, record the face and
    the barycentrics (best (n, m), bary (n, m, 3), updated in place)."""
    a, b, c = (uvs[face, i][:, None, :] for i in range(3))
    q = tries_uv[row]
    det = (b[..., 0] - a[..., 0]) * (c[..., 1] - a[..., 1]) - (c[..., 0] - a[..., 0]) * (b[..., 1] - a[..., 1])
    det = np.where(np.abs(det) < 1e-18, np.nan, det)  # a zero-area UV triangle holds no point
    w1 = ((q[..., 0] - a[..., 0]) * (c[..., 1] - a[..., 1]) - (c[..., 0] - a[..., 0]) * (q[..., 1] - a[..., 1])) / det
    w2 = ((b[..., 0] - a[..., 0]) * (q[..., 1] - a[..., 1]) - (q[..., 0] - a[..., 0]) * (b[..., 1] - a[..., 1])) / det
    w0 = 1.0 - w1 - w2
    pair, t = np.nonzero((w0 >= 0.0) & (w1 >= 0.0) & (w2 >= 0.0))
    key = row[pair] * best.shape[1] + t
    lowest = best.reshape(-1).copy()
    np.minimum.at(lowest, key, face[pair])  # each try's first triangle so far
    won = face[pair] == lowest[key]
    best.reshape(-1)[:] = lowest
    bary.reshape(-1, 3)[key[won]] = np.stack([w0[pair, t], w1[pair, t], w2[pair, t]], axis=1)[won]
