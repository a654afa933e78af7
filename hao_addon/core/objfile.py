# SPDX-License-Identifier: GPL-3.0-or-later
"""Minimal Wavefront OBJ reader for tests and benchmarks (v, vt, f; polygons fan-triangulated).

The add-on itself imports files through Blender's importers; this reader lets the pure-numpy
references and benchmarks load the same meshes without bpy.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from .geometry import TriangleSoup


def read_obj(path: str | Path) -> tuple[np.ndarray, np.ndarray, np.ndarray | None, np.ndarray | None]:
    """Returns (vertices (V, 3) float64, triangles (F, 3) int64, uvs (T, 2) float64 or None,
    triangle_uv_indices (F, 3) int64 or None)."""
    verts, uvs, tris, tri_uv = [], [], [], []
    has_uv = True
    with open(path, encoding="utf-8", errors="replace") as fh:
        for line in fh:
            if line.startswith("v "):
                verts.append([float(x) for x in line.split()[1:4]])
            elif line.startswith("vt "):
                uvs.append([float(x) for x in line.split()[1:3]])
            elif line.startswith("f "):
                corners = [c.split("/") for c in line.split()[1:]]
                vi = [int(c[0]) for c in corners]
                ti = [int(c[1]) if len(c) > 1 and c[1] else 0 for c in corners]
                has_uv &= all(t != 0 for t in ti)
                for k in range(1, len(vi) - 1):
                    tris.append([vi[0], vi[k], vi[k + 1]])
                    tri_uv.append([ti[0], ti[k], ti[k + 1]])
    v = np.array(verts, dtype=np.float64)
    t = np.array(tris, dtype=np.int64)
    t = np.where(t > 0, t - 1, t + len(v))  # OBJ indices are 1-based; negatives count back
    if not (has_uv and uvs):
        return v, t, None, None
    uv = np.array(uvs, dtype=np.float64)
    tu = np.array(tri_uv, dtype=np.int64)
    tu = np.where(tu > 0, tu - 1, tu + len(uv))
    return v, t, uv, tu


def obj_soup(path: str | Path, uvs: str = "file", size: int = 1024) -> TriangleSoup:
    """A TriangleSoup from an OBJ. uvs: 'file' (must have them), 'auto' (unwrap: core/bake/unwrap.py) or 'none'."""
    v, t, uv, tu = read_obj(path)
    if uvs == "file":
        if uv is None:
            raise ValueError(f"{path} has no UVs")
        corner_uv = uv[tu]
    elif uvs == "auto":
        from .bake.unwrap import unwrap_in_process
        corner_uv = unwrap_in_process(v, t, size)
    else:
        corner_uv = None
    return TriangleSoup(v[t], corner_uv, name=Path(path).stem)
