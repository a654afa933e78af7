# SPDX-License-Identifier: GPL-3.0-or-later
"""Bake groups of Blender mesh objects matched by name (core/bake/name_groups.py): the
objects' names, or their collection's, against the job options' suffixes."""
from __future__ import annotations

from ..core.bake.job_options import JobOptions
from ..core.bake.name_groups import match_groups
from .bake_request import BakeGroup


def collection_name(obj) -> str:
    """The name of the collection the object is in ('' for the scene's own collection)."""
    import bpy

    for collection in obj.users_collection:
        if collection != bpy.context.scene.collection:
            return collection.name
    return ""


def bake_groups(objects: list, options: JobOptions) -> tuple[list[BakeGroup], list[str]]:
    """The bake groups of the mesh objects, in their order, and one warning each for the
    meshes that match no group and the high-poly meshes without a low-poly (not baked)."""
    meshes = [o for o in objects if o.type == 'MESH']
    match = match_groups([(o.name, collection_name(o)) for o in meshes], options.low_suffix, options.high_suffix)
    by_name = {o.name: o for o in meshes}
    groups = [BakeGroup(g.name, [by_name[n] for n in g.lows], [by_name[n] for n in g.highs]) for g in match.groups]
    low, high = options.low_suffix, options.high_suffix
    notes = []
    if match.unmatched:
        notes.append(f"bake groups: {_names(match.unmatched)} match no group (a name or collection ending in "
                     f"'{low}' or '{high}'): not baked" + (", occluding every group (Group Occluders: all)"
                                                          if options.group_occluders == "all" else ""))
    if match.orphans:
        verb = "has" if len(match.orphans) == 1 else "have"
        notes.append(f"bake groups: high-poly {_names(match.orphans)} {verb} no low-poly ending in '{low}': "
                     f"not baked")
    return groups, notes


def _names(names: tuple[str, ...]) -> str:
    shown = ", ".join(f"'{n}'" for n in names[:10])
    return shown + (f" and {len(names) - 10} more" if len(names) > 10 else "")
