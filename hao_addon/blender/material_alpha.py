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
from ..core.errors import BakeInputError
from .mesh_arrays import loop_uvs


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


def material_alpha(material) -> tuple[float, "bpy.types.Node | None", str]:
    """(constant alpha, the Image Texture node of its alpha or None, a note: '' or why it is
    read as opaque) of a material. A NaN or infinite Alpha is refused (BakeInputError)."""
    bsdf = principled_bsdf(material)
    if bsdf is None:
        tree = compat.material_node_tree(material)
        shows = material is not None and tree is not None and any(n.type == 'OUTPUT_MATERIAL' for n in tree.nodes)
        return 1.0, None, (f"material '{material.name}' is not a Principled BSDF: read as opaque" if shows else "")
    alpha = bsdf.inputs['Alpha']
    if not alpha.is_linked:
        value = float(alpha.default_value)
        if not np.isfinite(value):
            raise BakeInputError(f"material '{material.name}' has an Alpha of {value}: set a value from 0 to 1")
        return value, None, ""
    node = _alpha_image_node(alpha)
    note = "" if node is not None else \
        f"material '{material.name}': its Alpha comes from nodes other than an image's alpha: read as opaque"
    return 1.0, node, note


# The largest alpha texture read at full size; a larger one is read at a power-of-two
# fraction no smaller than the bake's resolution can use (a 16k texture took 6.9 GB for a
# 64^2 bake: read whole, as Blender's float pixels, for one opacity per texel).
MAX_ALPHA_SIDE = 4096


def image_alpha(image: "bpy.types.Image", material_name: str = "", bake_size: int = MAX_ALPHA_SIDE) -> np.ndarray:
    """(H, W) float32 alpha channel of an image, row 0 at v = 0, read at no more than
    max(MAX_ALPHA_SIDE, 4 x bake_size) texels a side (a box-filtered copy where larger).
    An image whose file cannot be read is refused, naming it and its material."""
    w, h = image.size
    if w * h == 0:  # a missing or unreadable file loads as an image of no pixels
        where = f" ({image.filepath})" if image.filepath else ""
        raise BakeInputError(f"the image '{image.name}'{where} that gives material '{material_name}' its alpha "
                             f"cannot be read: restore the file, or bake with Alpha off (--alpha off)")
    limit = max(MAX_ALPHA_SIDE, 4 * bake_size)
    scale = 1
    while max(w, h) // scale > limit:
        scale *= 2
    # A copy reloads its pixels from the file: an image edited in Blender and not saved is read whole.
    if scale == 1 or image.source != 'FILE' or image.is_dirty or image.packed_file is not None:
        pixels = np.empty(w * h * 4, np.float32)
        image.pixels.foreach_get(pixels)
        return pixels.reshape(h, w, 4)[..., 3].copy()
    copy = image.copy()
    try:
        copy.scale(max(1, w // scale), max(1, h // scale))
        sw, sh = copy.size
        pixels = np.empty(sw * sh * 4, np.float32)
        copy.pixels.foreach_get(pixels)
        return pixels.reshape(sh, sw, 4)[..., 3].copy()
    finally:
        bpy.data.images.remove(copy)


def texture_uv_map(node, mesh: bpy.types.Mesh) -> str | None:
    """The UV map an Image Texture node reads: its UV Map node's, else the active render one."""
    vector = node.inputs['Vector']
    if vector.is_linked and vector.links[0].from_node.type == 'UVMAP' and vector.links[0].from_node.uv_map:
        return vector.links[0].from_node.uv_map
    active = next((layer for layer in mesh.uv_layers if layer.active_render), None)
    return active.name if active is not None else None


def soup_alpha(obj: bpy.types.Object, mesh: bpy.types.Mesh, tri_loops: np.ndarray,
               bake_size: int = MAX_ALPHA_SIDE) -> SoupAlpha | None:
    """The alpha of an evaluated mesh's triangles (tri_loops (F, 3), evaluated_soup's corner
    order), or None when every face is opaque and nothing was read as opaque for want of
    a better reading (else its notes say what)."""

    materials = [slot.material for slot in obj.material_slots] or [None]
    found = [material_alpha(m) for m in materials]
    notes = tuple(f"'{obj.name}': {note}" for _c, _n, note in found if note)
    found = [(c, node) for c, node, _note in found]
    if all(c >= 1.0 and node is None for c, node in found):
        return SoupAlpha(np.ones(len(tri_loops), np.float32), notes=notes) if notes else None
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
        images.append(image_alpha(node.image, materials[k].name, bake_size))
    if not images:
        return SoupAlpha(constant, notes=notes)
    return SoupAlpha(constant, images, index, uvs, notes)
