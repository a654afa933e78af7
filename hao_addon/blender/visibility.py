# SPDX-License-Identifier: GPL-3.0-or-later
"""Which meshes occlude a bake, as Cycles' bake takes them: those that render. Disable in
Renders (on the object or a collection above it) leaves a mesh out; hiding it in the viewport
(the eye) does not, as it does not leave it out of a render. A collection excluded from the
view layer holds no object of it."""
from __future__ import annotations

import bpy


def rendered_collections(scene: bpy.types.Scene) -> set[str]:
    """The names of the scene's collections whose path from the scene's own renders."""
    out, stack = set(), [scene.collection]
    while stack:
        collection = stack.pop()
        out.add(collection.name)
        stack.extend(child for child in collection.children if not child.hide_render)
    return out


def rendered_meshes(view_layer: bpy.types.ViewLayer, scene: bpy.types.Scene) -> list[bpy.types.Object]:
    """The view layer's mesh objects that render (module docstring), in its order."""
    collections = rendered_collections(scene)
    return [o for o in view_layer.objects if o.type == 'MESH' and not o.hide_render
            and any(c.name in collections for c in o.users_collection)]
