# SPDX-License-Identifier: GPL-3.0-or-later
"""A mesh's roughness and metallic per texel of a UV layout (for the ORM texture, core/bake/
orm.py): the Principled BSDF's Roughness and Metallic inputs of each face's material, a value
or an Image Texture wired to it (directly: its first channel; or through Separate Color: the
channel it takes, as Blender's glTF importer wires a metallicRoughness texture), sampled on
the UV map the texture node reads."""
from __future__ import annotations

import numpy as np

from ..core.bake.orm import channel_map, sample_nearest
from ..core.errors import BakeInputError
from .material_alpha import principled_bsdf, texture_uv_map
from .mesh_arrays import loop_uvs, mesh_arrays

CHANNELS = {"Red": 0, "Green": 1, "Blue": 2, "R": 0, "G": 1, "B": 2}


def _source(material, name: str) -> tuple[float, object, int]:
    """(value, Image Texture node or None, its channel) of a Principled input."""
    bsdf = principled_bsdf(material)
    if bsdf is None:
        return (0.5 if name == "Roughness" else 0.0), None, 0
    socket = bsdf.inputs[name]
    if not socket.is_linked:
        return float(socket.default_value), None, 0
    link = socket.links[0]
    node, channel = link.from_node, 0
    if node.type in ('SEPARATE_COLOR', 'SEPRGB', 'SEPARATE_RGB'):
        channel = CHANNELS.get(link.from_socket.name, 0)
        inner = node.inputs[0]
        node = inner.links[0].from_node if inner.is_linked else None
    if node is not None and node.type == 'TEX_IMAGE' and node.image is not None:
        return 1.0, node, channel
    raise BakeInputError(f"--orm-out: the {name} of material '{material.name}' comes from nodes other than a value "
                         f"or an Image Texture ({node.type if node is not None else 'nothing'})")


def _pixels(image) -> np.ndarray:
    w, h = image.size
    pixels = np.empty(w * h * 4, np.float32)
    image.pixels.foreach_get(pixels)
    return pixels.reshape(h, w, 4)


def roughness_metallic(obj, depsgraph, uvs: np.ndarray, size: int, margin: int) -> tuple[np.ndarray, np.ndarray]:
    """((size, size) roughness, (size, size) metallic) of the object's evaluated mesh in the
    layout uvs (F, 3, 2: its triangles in evaluated_soup's order on the baked UV map)."""

    obj_eval = obj.evaluated_get(depsgraph)
    mesh = obj_eval.to_mesh()
    try:
        _co, _tri_verts, tri_loops = mesh_arrays(mesh)
        if np.linalg.det(np.array(obj_eval.matrix_world)[:3, :3]) < 0.0:
            tri_loops = tri_loops[:, ::-1]
        polygon = np.empty(len(mesh.loop_triangles), np.int64)
        mesh.loop_triangles.foreach_get("polygon_index", polygon)
        slot = np.zeros(len(mesh.polygons), np.int64)
        mesh.polygons.foreach_get("material_index", slot)
        materials = [s.material for s in obj.material_slots] or [None]
        face_slot = np.clip(slot[polygon], 0, len(materials) - 1)
        out = []
        for name in ("Roughness", "Metallic"):
            sources = [_source(m, name) for m in materials]
            images = {k: (_pixels(node.image), loop_uvs(mesh, texture_uv_map(node, mesh))[tri_loops], channel)
                      for k, (_v, node, channel) in enumerate(sources) if node is not None}

            def face_value(face, bary, sources=sources, images=images):
                value = np.array([v for v, _n, _c in sources], np.float32)[face_slot[face]]
                for k, (pixels, image_uvs, channel) in images.items():
                    here = face_slot[face] == k
                    uv = np.einsum("mk,mkd->md", bary[here], image_uvs[face[here]])
                    value[here] = sample_nearest(pixels, uv)[:, channel]
                return np.clip(value, 0.0, 1.0)
            out.append(channel_map(uvs, size, face_value, margin))
        return out[0], out[1]
    finally:
        obj_eval.to_mesh_clear()
