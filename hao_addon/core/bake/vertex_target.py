# SPDX-License-Identifier: GPL-3.0-or-later
"""The colour-attribute target (Cycles: Bake > Target > Color Attributes): AO per mesh
vertex or per face corner instead of per texel, no UVs needed.

As Blender's bake defines it (editors/object/object_bake_api.cc,
bake_targets_populate_pixels_color_attributes and bake_targets_output_vertex_colors): one
sample per face corner, at its vertex, in the first triangle that holds the corner, shaded
with that corner's normal (smooth, sharp, custom, as the mesh is); the corner domain keeps
each corner's value, the point domain averages a vertex's corners. Here each corner is a
receiver whose "texel" is its output element (its corner index, or its vertex index), and
the per-element sums (estimators.texel_sums, every receiver weighing 1) are that average.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .settings import COLOR_DOMAIN_CHOICES

DOMAINS = tuple(c.value for c in COLOR_DOMAIN_CHOICES)


@dataclass
class VertexTarget:
    """cells: (F, 3) int64, the output element of each corner of the target's triangles (in
    TriangleSoup order), -1 where that face corner was already sampled in an earlier triangle;
    count: the number of elements (the mesh's vertices or corners); domain: 'point' or
    'corner'."""

    cells: np.ndarray
    count: int
    domain: str = "point"


def vertex_target(tri_loops: np.ndarray, loop_vertex: np.ndarray, domain: str,
                  vertex_count: int | None = None) -> VertexTarget:
    """The target of triangles whose corners are the face corners tri_loops (F, 3) int64 of a
    mesh of vertex_count vertices (default: the highest one used, + 1; loose vertices count
    too, keeping the unoccluded 1.0) whose corner l lies on vertex loop_vertex[l] (L,);
    domain 'point' or 'corner'. The first triangle that holds a face corner samples it
    (Blender's order)."""
    if domain not in DOMAINS:
        raise ValueError(f"unknown colour-attribute domain '{domain}', expected one of {DOMAINS}")
    flat = np.asarray(tri_loops, np.int64).ravel()
    first = np.zeros(len(flat), bool)
    first[np.unique(flat, return_index=True)[1]] = True
    cells = np.where(first, flat if domain == "corner" else np.asarray(loop_vertex, np.int64)[flat], -1)
    if vertex_count is None:
        vertex_count = int(np.max(loop_vertex, initial=-1)) + 1
    count = len(loop_vertex) if domain == "corner" else int(vertex_count)
    return VertexTarget(cells.reshape(-1, 3), count, domain)


def indexed_vertex_target(triangles: np.ndarray, vertex_count: int) -> VertexTarget:
    """The point-domain target of an indexed mesh (triangles (F, 3) int64 vertex indices, as
    an OBJ file holds them) with one corner per triangle corner."""
    tri = np.asarray(triangles, np.int64)
    return VertexTarget(tri.copy(), int(vertex_count), "point")
