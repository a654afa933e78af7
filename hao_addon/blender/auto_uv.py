# SPDX-License-Identifier: GPL-3.0-or-later
"""A UV map for a mesh that has none (Blender glue over core/bake/unwrap.py): the fast unwrap
(planar charts packed by xatlas) and, where the map as Blender wrote it still overlaps,
xatlas' own charts; a map that overlaps either way is refused (a bake into it is wrong)."""
from __future__ import annotations

from typing import Generator

import bpy

from ..core.bake.unwrap import UnwrapError, check_unwrap_overlap, unwrap_steps
from . import mesh_data

# The ways tried in order (core/bake/unwrap_worker.UNWRAPS), each with its status line.
WAYS = (("charts", "Unwrapping '{name}'"),
        ("xatlas", "Unwrapping '{name}' again with xatlas' own charts (the fast unwrap overlapped)"))


def unwrapped_steps(obj: bpy.types.Object, size: int, created: list
                    ) -> Generator[tuple[str, str], None, tuple[str, str]]:
    """Add mesh_data.AO_UV_NAME to obj's mesh, unwrapped for a size^2 map; yields (way,
    status) while the unwrap runs; returns (the map's name, a note: '' or which way made
    it). created: (mesh, name) of each map added, for the caller to remove on failure."""
    mesh = obj.data
    positions, tris, tri_loops, polygons = mesh_data.base_mesh_triangles(obj)
    failure = None
    for way, status in WAYS:
        steps = unwrap_steps(positions, tris, size, name=obj.name, polygons=polygons, way=way)
        try:
            while True:
                next(steps)
                yield way, status.format(name=obj.name)
        except StopIteration as done:
            uvs = done.value
        except UnwrapError as exc:
            failure = failure or exc
            continue
        finally:
            steps.close()
        name = mesh_data.add_uv_layer(mesh, mesh_data.AO_UV_NAME, tri_loops, uvs)
        created.append((mesh, name))
        try:
            check_unwrap_overlap(mesh_data.written_triangle_uvs(mesh, name, tri_loops), size, obj.name)
        except UnwrapError as exc:
            failure = failure or exc
            mesh.uv_layers.remove(mesh.uv_layers[name])
            created.remove((mesh, name))
            continue
        note = "" if way == WAYS[0][0] else f"'{obj.name}': the fast unwrap overlapped; unwrapped with xatlas' own charts"
        return name, note
    raise failure
