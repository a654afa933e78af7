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


def texel_surface_samples(uvs: np.ndarray, size: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """For every texel whose centre lies in a UV triangle, that triangle and the barycentric
    coordinates of the centre.

    uvs: (F, 3, 2) UV corners in [0, 1]. Returns (face_index (size, size) int64, -1 where
    uncovered; bary (size, size, 3) float64, inset_barycentrics' where covered; hits (size, size) int32: how many triangles
    contain the centre (> 1 where UV islands overlap)). Row y holds v = (y + 0.5) / size.
    """
    face = np.full((size, size), -1, dtype=np.int64)
    bary = np.zeros((size, size, 3), dtype=np.float64)
    hits = np.zeros((size, size), dtype=np.int32)
    p = uvs * size - 0.5  # texel-centre coordinates: centre of texel i is at i
    lo = np.clip(np.ceil(p.min(axis=1) - 1e-9), 0, size - 1).astype(np.int64)
    hi = np.clip(np.floor(p.max(axis=1) + 1e-9), 0, size - 1).astype(np.int64)
    for f in range(len(uvs)):
        (x0, y0), (x1, y1) = lo[f], hi[f]
        if x1 < x0 or y1 < y0:
            continue
        a, b, c = p[f]
        det = (b[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (b[1] - a[1])
        if abs(det) < 1e-12:
            continue  # zero-area UV triangle covers no texel centre
        ys, xs = np.mgrid[y0:y1 + 1, x0:x1 + 1]
        w1 = ((xs - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (ys - a[1])) / det
        w2 = ((b[0] - a[0]) * (ys - a[1]) - (xs - a[0]) * (b[1] - a[1])) / det
        w0 = 1.0 - w1 - w2
        inside = (w0 >= -1e-9) & (w1 >= -1e-9) & (w2 >= -1e-9)
        if not inside.any():
            continue
        yy, xx = ys[inside], xs[inside]
        first = face[yy, xx] < 0
        face[yy[first], xx[first]] = f
        bary[yy[first], xx[first]] = np.stack([w0[inside], w1[inside], w2[inside]], axis=1)[first]
        strict = (w0 > 1e-7) & (w1 > 1e-7) & (w2 > 1e-7)
        hits[ys[strict], xs[strict]] += 1
    covered = face >= 0
    bary[covered] = inset_barycentrics(bary[covered])
    return face, bary, hits


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
