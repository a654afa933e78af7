# SPDX-License-Identifier: GPL-3.0-or-later
"""Curvature and cavity maps of a mesh's own surface, in its UV layout (numpy only).

Mean curvature H at each vertex from the cotangent Laplacian (Meyer et al. 2003, with the
barycentric area): the Laplace-Beltrami operator of the position is -2 H n, so
H = -(L x . n) / 2, positive where the surface is convex (a sphere of radius R: 1 / R), 0 on a
plane, negative in a groove. Each texel takes H at its centre's point on the surface
(interpolated from its triangle's corners), made dimensionless by the target's bounding-sphere
radius r (k = H r: 1 for a sphere that fills its bounds, whatever its size) and encoded as
Substance and Marmoset bake these maps:
- curvature: 0.5 + 0.5 k / CURVATURE_RANGE, clipped to [0, 1]: mid-grey where flat, brighter
  on convex edges, darker in concave ones;
- cavity: 1 + min(k, 0) / CAVITY_RANGE, clipped to [0, 1]: white on flat and convex surface,
  darker in grooves and crevices.
Margins are grown as the AO map's (core/bake/seams.finalize_map).
"""
from __future__ import annotations

import numpy as np

from ..geometry import TriangleSoup, bounding_sphere, face_normals_areas, weld
from .seams import finalize_map
from .uv_raster import texel_surface_samples

# k = H r at which the maps saturate: features of a sixteenth of the object's radius are
# full white (convex) or black (concave) in the curvature map, of an eighth in the cavity map.
CURVATURE_RANGE = 16.0
CAVITY_RANGE = 8.0


def vertex_mean_curvature(positions: np.ndarray) -> np.ndarray:
    """(F, 3) mean curvature at each corner of (F, 3, 3) triangles (corners welded where
    bit-identical), convex positive: -(L x . n) / 2 with L the cotangent Laplacian over the
    barycentric vertex area and n the area-weighted vertex normal."""
    positions = np.asarray(positions, np.float64)
    first, inverse = weld(positions.reshape(-1, 3))
    verts, tri = positions.reshape(-1, 3)[first], inverse.reshape(-1, 3)
    normals, areas = face_normals_areas(positions)
    laplace = np.zeros((len(verts), 3))
    for c in range(3):  # the corner c's angle weighs the edge opposite it
        a, b = tri[:, (c + 1) % 3], tri[:, (c + 2) % 3]
        u, v = verts[a] - verts[tri[:, c]], verts[b] - verts[tri[:, c]]
        cross = np.linalg.norm(np.cross(u, v), axis=1)
        cot = np.divide(np.einsum("ij,ij->i", u, v), cross, out=np.zeros(len(tri)), where=cross > 0.0)
        edge = (0.5 * cot)[:, None] * (verts[b] - verts[a])
        np.add.at(laplace, a, edge)
        np.add.at(laplace, b, -edge)
    area = np.zeros(len(verts))
    normal = np.zeros((len(verts), 3))
    for c in range(3):
        np.add.at(area, tri[:, c], areas / 3.0)
        np.add.at(normal, tri[:, c], normals * areas[:, None])
    normal /= np.maximum(np.linalg.norm(normal, axis=1), 1e-300)[:, None]
    mean = -0.5 * np.einsum("ij,ij->i", laplace, normal) / np.maximum(area, 1e-300)
    return mean[tri]


def texel_curvature(target: TriangleSoup, size: int) -> tuple[np.ndarray, np.ndarray]:
    """(k (size, size) float64: H r at each covered texel centre's surface point, 0 elsewhere;
    covered (size, size) bool) of a target with UVs; r its bounding-sphere radius."""
    face, bary, _hits = texel_surface_samples(target.uvs, size)
    covered = face >= 0
    corner = vertex_mean_curvature(target.positions)
    k = np.zeros((size, size))
    k[covered] = np.einsum("nk,nk->n", bary[covered], corner[face[covered]])
    radius = bounding_sphere(target.positions.reshape(-1, 3))[1]
    return k * (radius if radius > 0.0 else 1.0), covered


def _encoded_map(values: np.ndarray, covered: np.ndarray, margin: int) -> np.ndarray:
    coverage = covered.astype(np.float64)
    return finalize_map(values * coverage, coverage, margin, background=0.0)[0]


def curvature_map(target: TriangleSoup, size: int, margin: int) -> np.ndarray:
    """(size, size) float32 curvature map: 0.5 + 0.5 k / CURVATURE_RANGE, clipped."""
    k, covered = texel_curvature(target, size)
    return _encoded_map(np.clip(0.5 + 0.5 * k / CURVATURE_RANGE, 0.0, 1.0), covered, margin)


def cavity_map(target: TriangleSoup, size: int, margin: int) -> np.ndarray:
    """(size, size) float32 cavity map: 1 + min(k, 0) / CAVITY_RANGE, clipped."""
    k, covered = texel_curvature(target, size)
    return _encoded_map(np.clip(1.0 + np.minimum(k, 0.0) / CAVITY_RANGE, 0.0, 1.0), covered, margin)
