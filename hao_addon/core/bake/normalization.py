# SPDX-License-Identifier: GPL-3.0-or-later
"""The exact normalization constant of the discrete AO sum (replacing the paper's heuristic).

McGraw & Sowers' equation 8 sums (w_d . n)|J| over the visible texels of every direction d
and then scale the map so that its brightest texel is 1, assuming some texel is unoccluded.
That assumption fails on enclosed or contact-heavy meshes and makes values depend on the
rest of the map. Here each triangle f with unit normal n_f gets the constant

    S_f = sum_d weight(w_d . n_f),   weight(c) = max(c, 0) (cosine) or [c > 0] (uniform),

the value the sum reaches when nothing occludes f. Dividing every contribution of f by S_f
makes an unoccluded texel exactly 1 for any direction set, and a partly occluded one the
discrete estimate of the cosine- (or uniformly) weighted visible fraction of its hemisphere.
"""
from __future__ import annotations

import numpy as np

WEIGHTINGS = ("cosine", "uniform")


def hemisphere_weight(cos_theta: np.ndarray, weighting: str, spread_cos: float = 0.0) -> np.ndarray:
    """Per-direction weight of the estimator for cos(theta) = w . n; directions outside the
    spread cone (cos(theta) < spread_cos, the cosine of the Spread Angle; 0: the hemisphere)
    weigh nothing."""
    if weighting == "cosine":
        weight = np.maximum(cos_theta, 0.0)
    elif weighting == "uniform":
        weight = (cos_theta > 0.0).astype(np.asarray(cos_theta).dtype)
    else:
        raise ValueError(f"unknown weighting '{weighting}', expected one of {WEIGHTINGS}")
    return weight if spread_cos <= 0.0 else np.where(cos_theta >= spread_cos, weight, 0.0).astype(weight.dtype)


# Products computed at once, at most: a block's numpy calls stay short (a signal is acted on
# between them, not after a second-long product: 14k faces x 16384 directions in one block
# held Ctrl-C for 0.8 s and 0.9 GB) and the block stays in cache. At 256 directions the
# blocks are 8192 faces (4096 corners), as before.
FACE_BLOCK = 1 << 21
CORNER_BLOCK = 1 << 20


def _rows(block: int, directions: np.ndarray) -> int:
    return max(1, block // max(1, len(directions)))


def face_normalizers(normals: np.ndarray, directions: np.ndarray, weighting: str = "cosine",
                     block: int = FACE_BLOCK, spread_cos: float = 0.0) -> np.ndarray:
    """S_f for each face.

    normals: (F, 3) unit face normals (zero rows for degenerate faces);
    directions: (D, 3) unit directions; block: products per step (faces x directions).
    Returns (F,) float64; 0 where no direction sees the face.

    float32 products and sums (relative error ~1e-6, four times faster than float64: 0.14 s
    -> 0.03 s for 69k faces x 256 directions). Exactness does not rest on S_f: an open texel
    is 1 because numerator and denominator carry the same 1 / S_f; S_f only balances faces
    that share a texel (seams, overlapping islands).
    """
    if weighting not in WEIGHTINGS:
        raise ValueError(f"unknown weighting '{weighting}', expected one of {WEIGHTINGS}")
    normals = np.asarray(normals, dtype=np.float32)
    dirs_t = np.ascontiguousarray(np.asarray(directions, dtype=np.float32).T)
    ones = np.ones(dirs_t.shape[1], np.float32)
    out = np.empty(len(normals), dtype=np.float64)
    chunk = _rows(block, directions)
    for start in range(0, len(normals), chunk):
        block = normals[start:start + chunk] @ dirs_t  # (chunk, D)
        if spread_cos > 0.0:
            block = hemisphere_weight(block, weighting, spread_cos).astype(np.float32)
        elif weighting == "cosine":
            np.maximum(block, 0.0, out=block)
        else:
            block = (block > 0.0).astype(np.float32)
        out[start:start + chunk] = block @ ones  # BLAS row sums
    return out


def corner_normalizers(shading: np.ndarray, face_normals: np.ndarray, directions: np.ndarray,
                       weighting: str = "cosine", block: int = CORNER_BLOCK, spread_cos: float = 0.0
                       ) -> tuple[np.ndarray, np.ndarray]:
    """S and its above-face part at every corner of shaded faces.

    shading: (F, 3, 3) unit corner shading normals; face_normals: (F, 3) unit face normals;
    directions: (D, 3). Returns (S (F, 3), S_above (F, 3)) float64: sum_d weight(w_d . n_s),
    and the same over the directions with w_d . n_f > 0 (those the true surface can see).
    float32 products as in face_normalizers.
    """
    if weighting not in WEIGHTINGS:
        raise ValueError(f"unknown weighting '{weighting}', expected one of {WEIGHTINGS}")
    dirs_t = np.ascontiguousarray(np.asarray(directions, dtype=np.float32).T)
    ones = np.ones(dirs_t.shape[1], np.float32)
    shading = np.asarray(shading, np.float32)
    faces = np.asarray(face_normals, np.float32)
    total = np.empty((len(faces), 3))
    above = np.empty((len(faces), 3))
    chunk = _rows(block, directions)
    for start in range(0, len(faces), chunk):
        up = (faces[start:start + chunk] @ dirs_t) > 0.0  # (chunk, D)
        for k in range(3):
            block = shading[start:start + chunk, k] @ dirs_t
            block = hemisphere_weight(block, weighting, spread_cos).astype(np.float32)
            total[start:start + chunk, k] = block @ ones
            above[start:start + chunk, k] = np.where(up, block, 0.0) @ ones
    return total, above
