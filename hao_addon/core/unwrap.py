# SPDX-License-Identifier: GPL-3.0-or-later
"""Automatic UV atlas with xatlas for meshes that have no UV map (CPU; no bpy)."""
from __future__ import annotations

import numpy as np


def xatlas_unwrap(vertices: np.ndarray, triangles: np.ndarray, resolution: int, padding: int = 4) -> np.ndarray:
    """Per-corner UVs in [0, 1] for a triangle mesh.

    vertices: (V, 3) float; triangles: (F, 3) int vertex indices. resolution: the texture
    size the atlas is packed for; padding: texels kept free around each chart (>= 2 so the
    bake's one-texel tent and bilinear lookups never mix charts).
    Returns (F, 3, 2) float64, corner k of triangle f at [f, k].
    """
    import xatlas  # shipped as a wheel with the extension

    atlas = xatlas.Atlas()
    atlas.add_mesh(np.ascontiguousarray(vertices, dtype=np.float32),
                   np.ascontiguousarray(triangles, dtype=np.uint32))
    chart_options = xatlas.ChartOptions()
    pack_options = xatlas.PackOptions()
    pack_options.resolution = int(resolution)
    pack_options.padding = int(padding)
    pack_options.bilinear = True
    atlas.generate(chart_options, pack_options)
    vmapping, indices, uvs = atlas[0]
    if len(indices) != len(triangles):
        raise RuntimeError(f"xatlas returned {len(indices)} triangles for {len(triangles)}")
    if atlas.atlas_count != 1:
        raise RuntimeError(f"xatlas packed {atlas.atlas_count} atlases; only one UV tile is supported")
    return np.asarray(uvs, dtype=np.float64)[np.asarray(indices)]
