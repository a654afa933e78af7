# SPDX-License-Identifier: GPL-3.0-or-later
"""Arrays read from a Blender mesh through its buffers (positions, triangles, UVs, corner
normals): what the soups (mesh_data.py), the materials' alpha and channels and the viewport's
scene read, below all of them."""
from __future__ import annotations

import bpy
import numpy as np


def read_positions(mesh: bpy.types.Mesh) -> np.ndarray:
    """(3 V,) float32 vertex positions through the 'position' attribute: the buffer path,
    about 40x faster than MeshVertex.co for 100k vertices (0.07 ms against 3 ms here)."""
    co = np.empty(len(mesh.vertices) * 3, np.float32)
    mesh.attributes["position"].data.foreach_get("vector", co)
    return co


def mesh_arrays(mesh: bpy.types.Mesh) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(vertex positions (V, 3), triangle vertex indices (F, 3), triangle loop indices (F, 3))."""
    mesh.calc_loop_triangles()
    co = read_positions(mesh).astype(np.float64)
    tri_verts = np.empty(len(mesh.loop_triangles) * 3, dtype=np.int64)
    mesh.loop_triangles.foreach_get("vertices", tri_verts)
    tri_loops = np.empty(len(mesh.loop_triangles) * 3, dtype=np.int64)
    mesh.loop_triangles.foreach_get("loops", tri_loops)
    return co.reshape(-1, 3), tri_verts.reshape(-1, 3), tri_loops.reshape(-1, 3)


def loop_uvs(mesh: bpy.types.Mesh, name: str) -> np.ndarray:
    """(L, 2) float64 UVs of every loop of the named UV map."""
    layer = mesh.uv_layers.get(name)
    if layer is None:
        raise KeyError(f"mesh '{mesh.name}' has no UV map named '{name}'")
    uv = np.empty(len(mesh.loops) * 2, dtype=np.float64)
    layer.uv.foreach_get("vector", uv)
    return uv.reshape(-1, 2)


def corner_normals(mesh: bpy.types.Mesh) -> np.ndarray:
    """(L, 3) float64 shading normal of every corner (loop) as Blender shades the mesh: face
    normals on flat faces, interpolated on smooth ones, with sharp edges, custom normals and
    Smooth by Angle applied (Mesh.corner_normals, Blender 4.1+)."""
    normals = np.empty(len(mesh.loops) * 3, np.float32)
    mesh.corner_normals.foreach_get("vector", normals)
    return normals.reshape(-1, 3).astype(np.float64)
