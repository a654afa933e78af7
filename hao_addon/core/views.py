# SPDX-License-Identifier: GPL-3.0-or-later
"""Orthographic light views for the outside-in baker.

Coordinates are first normalized in float64 (translate to the target's bounding-sphere
centre, divide by its radius) so the GPU's float32 sees values near [-1, 1] whatever the
scene's scale or distance from the origin: a mesh 1e5 units away keeps its precision.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass
class OrthoView:
    """One light view. matrix: (4, 4) float32 row-major clip-from-normalized-world.

    width, height: pixels of the sub-rectangle the view covers; all pixels are square with
    side pixel_size (normalized units). omega: (3,) unit direction towards the light.
    """

    matrix: np.ndarray
    width: int
    height: int
    omega: np.ndarray
    pixel_size: float
    depth_near: float
    depth_far: float


def light_basis(omega: np.ndarray) -> np.ndarray:
    """Rows u, v, w with w = omega and u x v = w (so front faces stay counter-clockwise)."""
    w = np.asarray(omega, dtype=np.float64)
    w = w / np.linalg.norm(w)
    helper = np.array([1.0, 0.0, 0.0]) if abs(w[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    u = np.cross(helper, w)
    u /= np.linalg.norm(u)
    v = np.cross(w, u)
    return np.stack([u, v, w])


def fit_view(omega: np.ndarray, target_points: np.ndarray, light_reach: float | None,
             pixel_size: float, jitter: np.ndarray, max_side: int) -> OrthoView:
    """Orthographic view looking along -omega that covers target_points (n, 3).

    The window is the tight projected box of the target (pixels elsewhere cannot hold a target
    texel, so they are never rasterized); the depth range runs from the target's farthest point
    to light_reach (the largest w . p over everything drawn, None = the target's own), so
    occluders between the target and the light are kept.
    jitter: (2,) in [0, 1) pixel offset, decorrelating the pixel grids of successive views.
    """
    basis = light_basis(omega)
    # (3, n) u, v, w rows: reductions along contiguous rows are about 5x faster than down the
    # columns of an (n, 3) array (this fit ran at 2.7 ms per view for 35k points).
    proj = basis @ np.asarray(target_points, np.float64).T
    lo_all, hi_all = proj.min(axis=1), proj.max(axis=1)
    lo = lo_all[:2] - pixel_size * (1.0 + jitter)
    hi = hi_all[:2] + pixel_size
    size = np.ceil((hi - lo) / pixel_size).astype(int)
    width, height = (int(min(max(s, 1), max_side)) for s in size)
    hi = lo + np.array([width, height]) * pixel_size  # square pixels exactly
    zlo, zhi = float(lo_all[2]), float(hi_all[2])
    if light_reach is not None:
        zhi = max(zhi, light_reach)
    pad = 1e-3 * max(zhi - zlo, 1e-6)
    zlo, zhi = zlo - pad, zhi + pad
    # NDC: x, y in [-1, 1] over the window; depth: w = zhi (nearest the light) -> -1, zlo -> +1.
    sx, sy = (float(x) for x in 2.0 / (hi - lo))
    tx, ty = (float(x) for x in -(hi + lo) / (hi - lo))
    sz = -2.0 / (zhi - zlo)
    tz = (zhi + zlo) / (zhi - zlo)
    ndc_from_uvw = np.array([[sx, 0, 0, tx],
                             [0, sy, 0, ty],
                             [0, 0, sz, tz],
                             [0, 0, 0, 1.0]], dtype=np.float64)
    uvw_from_world = np.eye(4)
    uvw_from_world[:3, :3] = basis
    matrix = (ndc_from_uvw @ uvw_from_world).astype(np.float32)
    return OrthoView(matrix, width, height, basis[2], pixel_size, float(zlo), float(zhi))
