# SPDX-License-Identifier: GPL-3.0-or-later
"""Instanced occluders: the meshes a scene shows through instancing (collection instances,
nested ones too, geometry-nodes instances, particle and vertex/face duplis), each with its
own world transform, as Cycles' bake sees them. They are no objects of the view layer, so a
list of its visible meshes misses them: a floor under a cube that an Empty instances baked
1.000 where the cube itself gives 0.958."""
from __future__ import annotations

import bpy

from ..core.geometry import TriangleSoup
from . import mesh_data


def instanced_soups(depsgraph: bpy.types.Depsgraph, alpha: bool = False, alpha_size: int = 4096
                    ) -> list[TriangleSoup]:
    """World-space soups (no UVs, no shading normals) of every mesh instance the evaluated
    scene shows (depsgraph.object_instances' is_instance entries), named
    'instancer/object'. Read inside the iteration: an instance is valid only there."""
    soups = []
    for instance in depsgraph.object_instances:
        if not instance.is_instance or instance.object.type != 'MESH':
            continue
        if instance.object.original.hide_render or (instance.parent is not None and instance.parent.original.hide_render):
            continue  # what does not render does not occlude (blender/visibility.py)
        parent = instance.parent.name if instance.parent is not None else "instance"
        soups.append(mesh_data.evaluated_soup(instance.object, depsgraph, None, shading_normals=False, alpha=alpha,
                                              alpha_size=alpha_size, matrix=instance.matrix_world,
                                              name=f"{parent}/{instance.object.name}"))
    return [soup for soup in soups if len(soup.positions)]
