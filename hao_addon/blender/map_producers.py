# SPDX-License-Identifier: GPL-3.0-or-later
"""The producers of the maps a bake job makes beside its AO result (core/bake/map_kinds.py):
the bent normals in the request's space and convention, and glTF's ORM texture from the
objects' materials, and those made from the surface alone (curvature, cavity). (Thickness is a
bake of its own: bake.thickness_steps.)"""
from __future__ import annotations

import numpy as np

from ..bake import BakeResult
from ..core.bake.map_kinds import EXTRA_MAPS
from ..core.bake.orm import orm_image
from ..core.bake.tangent_space import bent_normal_map
from ..core.bake.udim import udim_layout
from ..core.errors import BakeInputError
from ..core.geometry import TriangleSoup, face_normals_areas
from . import mesh_data
from .bake_request import BakeRequest
from .material_channels import roughness_metallic


def orm_map(request: BakeRequest, obj, depsgraph, target: TriangleSoup, result: BakeResult) -> np.ndarray:
    """(size, size, 4) ORM texture of a finished bake: its AO, the object's roughness and
    metallic in the baked UV layout (blender/material_channels.py)."""
    if result.tiles:
        raise BakeInputError("the ORM texture is a glTF texture, and glTF has no UDIM tiles: these UVs lie on "
                             "several; bake without --orm-out")
    settings = request.settings
    roughness, metallic = roughness_metallic(obj, depsgraph, target.uvs, settings.size, settings.margin)
    return orm_image(result.ao, roughness, metallic)


def bent_normal_image(request: BakeRequest, objects: list, depsgraph, uv_names: list[str], target: TriangleSoup,
                      result: BakeResult) -> np.ndarray:
    """(size, size, 4) encoded bent-normal image of a finished bake of objects (one, or a
    texture set's, whose target is their soups in that order), in the request's space."""
    linear = np.array(objects[0].evaluated_get(depsgraph).matrix_world, dtype=np.float64)[:3, :3]
    space, convention, margin = request.options.bent_space, request.options.bent_convention, request.settings.margin
    tangents = normals = None
    if space == "tangent":
        tangents = np.concatenate([mesh_data.corner_tangents(o, depsgraph, uv)
                                   for o, uv in zip(objects, uv_names)])
        # The world corner normals as they are (not re-normalized: on a scaled object that
        # would turn the decoded direction, 4 degrees on tests/test_bent_normals' sphere).
        normals = target.normals
        if normals is None:  # flat shading: every corner has its face's normal
            normals = np.repeat(face_normals_areas(target.positions)[0][:, None, :], 3, axis=1)
    if result.tiles is None:
        return bent_normal_map(result.bent_normals, result.covered, result.filled, margin, target.uvs, space,
                               convention, linear, tangents, normals)
    layout = udim_layout(target.uvs)  # one map per tile, from the tile's own triangles
    maps = []
    for tile in range(layout.count):
        faces, local = layout.local_uvs(target.uvs, tile)
        maps.append(bent_normal_map(result.bent_normals[tile], result.covered[tile], result.filled[tile],
                                    margin, local, space, convention, linear,
                                    None if tangents is None else tangents[faces],
                                    None if normals is None else normals[faces]))
    return np.stack(maps)


def surface_maps(request: BakeRequest, target: TriangleSoup, tiles: tuple[int, ...] | None) -> dict[str, np.ndarray]:
    """The maps made from the target's surface alone (core/bake/map_kinds.py: from_surface,
    such as curvature and cavity) that the request writes, by key."""
    made = {}
    for kind in EXTRA_MAPS:
        if kind.from_surface is None or not request.map_path(kind.key):
            continue
        if tiles:
            raise BakeInputError(f"{kind.noun} is made on one 0..1 tile, and these UVs lie on several UDIM tiles: "
                                 f"bake without {kind.flag}")
        made[kind.key] = kind.from_surface(target, request.settings.size, request.settings.margin)
    return made
