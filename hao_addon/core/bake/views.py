# SPDX-License-Identifier: GPL-3.0-or-later
"""Orthographic light views for the outside-in baker.

Coordinates are first normalized in float64 (translate to the target's bounding-sphere
centre, divide by its radius) so the GPU's float32 sees values near [-1, 1] whatever the
scene's scale or distance from the origin: a mesh 1e5 units away keeps its precision.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, replace

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
    # A view cropped from a whole one (a run of some texels, fit_views' window_points): that
    # view, and the whole view's pixel where the window of width x height pixels starts. Its
    # depth map is the whole view's, drawn in the window alone and read through the whole
    # view's matrix (the same pixel and depth arithmetic as the whole bake's).
    whole: "OrthoView | None" = None
    first: tuple[int, int] = (0, 0)

    def plane_slope(self) -> np.ndarray:
        """(2,) float64 c: a plane of normal g has depth (clip z / 2 + 1 / 2) slope
        c * m.xy / m.z per pixel in this view, m = M g for the matrix's linear part M. M = S R
        (scales S times the rotation of light_basis), so the clip-space normal M^-T g is
        S^-2 m, and its slope -n.xy / (n.z * size) is -(s_z / s_xy)^2 / size * m.xy / m.z,
        s_i the length of row i (gpu_shaders/bake_gather.comp, plane_lookup)."""
        rows = np.square(self.matrix[:3, :3].astype(np.float64)).sum(axis=1)
        return -rows[2] / (rows[:2] * np.array([self.width, self.height], np.float64))


def light_basis(omega: np.ndarray) -> np.ndarray:
    """Rows u, v, w with w = omega and u x v = w (so front faces stay counter-clockwise)."""
    # Scalar arithmetic: np.cross on 3-vectors costs ~0.1 ms each in call overhead.
    x, y, z = (float(c) for c in omega)
    n = math.sqrt(x * x + y * y + z * z)
    x, y, z = x / n, y / n, z / n
    if abs(x) < 0.9:  # u = (1, 0, 0) x w
        u = (0.0, -z, y)
    else:  # u = (0, 1, 0) x w
        u = (z, 0.0, -x)
    un = math.sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2])
    ux, uy, uz = u[0] / un, u[1] / un, u[2] / un
    v = (y * uz - z * uy, z * ux - x * uz, x * uy - y * ux)  # w x u
    return np.array([[ux, uy, uz], v, [x, y, z]])


def fit_view(omega: np.ndarray, target_points: np.ndarray, light_reach: float | None,
             pixel_size: float, jitter: np.ndarray, max_side: int) -> OrthoView:
    """Orthographic view looking along -omega that covers target_points (n, 3).

    The window is the tight projected box of the target (pixels elsewhere cannot hold a target
    texel, so they are never rasterized); the depth range runs from the target's farthest point
    to light_reach (the largest w . p over everything drawn, None = the target's own), so
    occluders between the target and the light are kept.
    jitter: (2,) in [0, 1) pixel offset, decorrelating the pixel grids of successive views.
    """
    return fit_views(np.asarray(omega)[None], target_points, [light_reach], pixel_size,
                     np.asarray(jitter)[None], max_side)[0]


def fit_views(omegas: np.ndarray, target_points: np.ndarray, light_reaches: list[float | None],
              pixel_size: float, jitters: np.ndarray, max_side: int,
              window_points: np.ndarray | None = None, window_spheres: np.ndarray | None = None
              ) -> list[OrthoView]:
    """fit_view for k directions at once: omegas (k, 3), light_reaches (k,), jitters (k, 2).
    One (3k, 3) x (3, n) product and one pass of row reductions serve all k views (per view,
    numpy's call overhead was most of the 0.5 ms a fit took on the bunny's 35k points).
    window_points: (m, 3) or None: each view is then the views of target_points cropped to
    the pixels that cover these points' projection, on the same pixel grid and depth range (a
    run of some texels reads the same depth-map values as the whole bake). window_spheres:
    (s, 4) or None: each view cropped to these spheres' projection instead."""
    bases = np.stack([light_basis(omega) for omega in omegas])  # (k, 3, 3)
    lo_rows, hi_rows = _projected_extents(bases, target_points)
    if window_spheres is not None:
        crops = zip(*_sphere_extents(bases, window_spheres))
    else:
        crops = [None] * len(bases) if window_points is None else zip(*_projected_extents(bases, window_points))
    return [_view_from_extent(basis, lo_all, hi_all, reach, pixel_size, jitter, max_side, crop)
            for basis, lo_all, hi_all, reach, jitter, crop in zip(bases, lo_rows, hi_rows, light_reaches, jitters,
                                                                  crops)]


def _projected_extents(bases: np.ndarray, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(k, 3) lowest and highest u, v, w of points (n, 3) in each basis of bases (k, 3, 3)."""
    # (3k, n) u, v, w rows: reductions along contiguous rows are about 5x faster than down the
    # columns of an (n, 3) array.
    proj = bases.reshape(-1, 3) @ np.asarray(points, np.float64).T
    return proj.min(axis=1).reshape(-1, 3), proj.max(axis=1).reshape(-1, 3)


def _sphere_extents(bases: np.ndarray, spheres: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(k, 3) lowest and highest u, v, w of spheres (s, 4) in each basis of bases (k, 3, 3)
    (orthonormal: a sphere spans its centre's coordinate plus and minus its radius)."""
    centres = np.einsum("kij,sj->ksi", bases, np.asarray(spheres, np.float64)[:, :3])
    radii = np.asarray(spheres, np.float64)[None, :, 3:]
    return (centres - radii).min(axis=1), (centres + radii).max(axis=1)


def _view_from_extent(basis: np.ndarray, lo_all: np.ndarray, hi_all: np.ndarray, light_reach: float | None,
                      pixel_size: float, jitter: np.ndarray, max_side: int,
                      crop: tuple[np.ndarray, np.ndarray] | None = None) -> OrthoView:
    """The view of light basis (3, 3) whose target spans lo_all..hi_all (3,) in u, v, w;
    with crop (its lowest and highest u, v, w), only its pixels that cover crop's u, v
    (and the one beyond each side), as a view cropped from the whole one (OrthoView.whole)."""
    lo = lo_all[:2] - pixel_size * (1.0 + jitter)
    hi = hi_all[:2] + pixel_size
    size = np.ceil((hi - lo) / pixel_size).astype(int)
    width, height = (int(min(max(s, 1), max_side)) for s in size)
    zlo, zhi = float(lo_all[2]), float(hi_all[2])
    if light_reach is not None:
        zhi = max(zhi, light_reach)
    pad = 1e-3 * max(zhi - zlo, 1e-6)
    whole = _ortho_view(basis, lo, (width, height), pixel_size, zlo - pad, zhi + pad)
    if crop is None:
        return whole
    # Whole pixels first..end of the whole view's grid.
    size = np.array([width, height])
    first = np.clip(np.floor((crop[0][:2] - pixel_size - lo) / pixel_size), 0, size - 1).astype(int)
    end = np.clip(np.ceil((crop[1][:2] + pixel_size - lo) / pixel_size), first + 1, size).astype(int)
    return replace(whole, width=int(end[0] - first[0]), height=int(end[1] - first[1]), whole=whole,
                   first=(int(first[0]), int(first[1])))


def _ortho_view(basis: np.ndarray, lo: np.ndarray, size, pixel_size: float, zlo: float, zhi: float) -> OrthoView:
    """The view of light basis (3, 3) whose window starts at u, v lo (2,) and is size (width,
    height) pixels, its depth range zlo..zhi."""
    width, height = int(size[0]), int(size[1])
    hi = lo + np.array([width, height]) * pixel_size  # square pixels exactly
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


def cell_corners(points: np.ndarray, cell: float) -> np.ndarray:
    """(k, 3) corners of the grid cells (side `cell`) that hold points (n, 3): a few points
    whose projection along any direction covers the points' (light views are fitted to them)."""
    if len(points) == 0:
        return np.zeros((1, 3))
    cells = np.floor(points / cell).astype(np.int64)
    low = cells.min(axis=0)
    span = cells.max(axis=0) - low + 1
    if np.prod(span.astype(np.float64)) < 2.0**62:
        # One int64 per cell: a 1-D unique (30 ms for 600k points; by rows 700 ms).
        packed = np.unique(((cells[:, 0] - low[0]) * span[1] + (cells[:, 1] - low[1])) * span[2] + (cells[:, 2] - low[2]))
        rest, z = np.divmod(packed, span[2])
        x, y = np.divmod(rest, span[1])
        keys = np.stack([x, y, z], axis=1) + low
    else:
        keys = np.unique(cells, axis=0)
    offsets = np.array([[i, j, k] for i in (0, 1) for j in (0, 1) for k in (0, 1)])
    return ((keys[:, None, :] + offsets[None]) * cell).reshape(-1, 3)


# The R2 sequence (Roberts 2018; 1/g, 1/g^2 with g the plastic number): pixel-grid offsets
# that cover the unit square evenly in any run of views, at no cost (seeding a numpy
# generator per view took 0.27 ms, 3 % of a light view).
_PLASTIC = 1.324717957244746
_R2_STEP = np.array([1.0 / _PLASTIC, 1.0 / _PLASTIC**2])


def pixel_jitter(seed: int, index: int) -> np.ndarray:
    """(2,) sub-pixel offset in [0, 1) of light view `index` of a bake with `seed`."""
    start = np.array([0.5, 0.5]) + (seed % 1_000_003) * np.array([0.7548776662466927, 0.5698402909980532])
    return np.mod(start + index * _R2_STEP, 1.0)
