# SPDX-License-Identifier: GPL-3.0-or-later
"""What an occluder's materials let through (core/bake/alpha.py): the Principled BSDF's
Alpha input, a value, or an Image Texture's alpha wired to it (directly, or through Math
nodes as Blender's glTF importer wires MASK materials; the cut-off is then the Alpha Clip
setting), sampled on the mesh's UVs as the texture node reads them."""
from __future__ import annotations

import bpy
import numpy as np

from .. import compat
from ..core.bake.alpha import SoupAlpha


def principled_bsdf(material) -> "bpy.types.Node | None":
    """The Principled BSDF the material's active output shows, or None."""
    tree = compat.material_node_tree(material)
    if tree is None:
        return None
    outputs = [n for n in tree.nodes if n.type == 'OUTPUT_MATERIAL']
    output = next((n for n in outputs if n.is_active_output), outputs[0] if outputs else None)
    if output is None or not output.inputs['Surface'].is_linked:
        return None
    node = output.inputs['Surface'].links[0].from_node
    return node if node.type == 'BSDF_PRINCIPLED' else None


def _alpha_image_node(socket) -> "bpy.types.Node | None":
    """The Image Texture whose Alpha reaches `socket`, directly or through Math nodes."""
    for _ in range(8):
        if not socket.is_linked:
            return None
        link = socket.links[0]
        node = link.from_node
        if node.type == 'TEX_IMAGE' and link.from_socket.name == 'Alpha' and node.image is not None:
            return node
        if node.type != 'MATH':
            return None
        socket = next((s for s in node.inputs if s.is_linked), None)
        if socket is None:
            return None
    return None


def material_alpha(material) -> tuple[float, "bpy.types.Node | None"]:
    """(constant alpha, the Image Texture node of its alpha or None) of a material; (1, None)
    for one that is opaque or whose alpha comes from nodes read here as opaque."""
    bsdf = principled_bsdf(material)
    if bsdf is None:
        return 1.0, None
    alpha = bsdf.inputs['Alpha']
    if not alpha.is_linked:
        return float(alpha.default_value), None
    return 1.0, _alpha_image_node(alpha)


def image_alpha(image: "bpy.types.Image") -> np.ndarray:
    """(H, W) float32 alpha channel of an image, row 0 at v = 0."""
    w, h = image.size
    pixels = np.empty(w * h * 4, np.float32)
    image.pixels.foreach_get(pixels)
    return pixels.reshape(h, w, 4)[..., 3].copy()


def texture_uv_map(node, mesh: bpy.types.Mesh) -> str | None:
    """The UV map an Image Texture node reads: its UV Map node's, else the active render one."""
    vector = node.inputs['Vector']
    if vector.is_linked and vector.links[0].from_node.type == 'UVMAP' and vector.links[0].from_node.uv_map:
        return vector.links[0].from_node.uv_map
    active = next((layer for layer in mesh.uv_layers if layer.active_render), None)
    return active.name if active is not None else None


def soup_alpha(obj: bpy.types.Object, mesh: bpy.types.Mesh, tri_loops: np.ndarray) -> SoupAlpha | None:
    """The alpha of an evaluated mesh's triangles (tri_loops (F, 3), evaluated_soup's corner
    order), or None when every face is opaque."""
    from .mesh_data import loop_uvs

    materials = [slot.material for slot in obj.material_slots] or [None]
    found = [material_alpha(m) for m in materials]
    if all(c >= 1.0 and node is None for c, node in found):
        return None
    polygon = np.empty(len(mesh.loop_triangles), np.int64)
    mesh.loop_triangles.foreach_get("polygon_index", polygon)
    slot = np.zeros(len(mesh.polygons), np.int64)
    mesh.polygons.foreach_get("material_index", slot)
    face_slot = np.clip(slot[polygon], 0, len(materials) - 1)
    constant = np.array([c for c, _node in found], np.float32)[face_slot]
    images, index, uvs = [], np.full(len(face_slot), -1, np.int64), None
    for k, (_c, node) in enumerate(found):
        uv_name = None if node is None else texture_uv_map(node, mesh)
        if uv_name is None:
            continue
        faces = face_slot == k
        if uvs is None:
            uvs = np.zeros((len(face_slot), 3, 2))
        uvs[faces] = loop_uvs(mesh, uv_name)[tri_loops[faces]]
        index[faces] = len(images)
        images.append(image_alpha(node.image))
    if not images:
        return SoupAlpha(constant)
    return SoupAlpha(constant, images, index, uvs)
