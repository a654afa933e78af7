# SPDX-License-Identifier: GPL-3.0-or-later
"""AO maps as Blender image datablocks, and wiring them into materials."""
from __future__ import annotations

import os
import shutil
import tempfile

import bpy
import numpy as np

AO_NODE_LABEL = "HAO AO"
AO_MIX_LABEL = "HAO AO Multiply"
# The node group Blender's glTF exporter reads the Occlusion input of (io_scene_gltf2:
# get_socket_from_gltf_material_node matches group names starting with this, any case), and
# writes as the material's occlusionTexture on the UV map of the image's UV Map node.
GLTF_OUTPUT_GROUP = "glTF Material Output"
GLTF_OCCLUSION = "Occlusion"


def gltf_output_group() -> bpy.types.NodeTree:
    """The 'glTF Material Output' node group with its Occlusion input (made as the glTF
    importer makes it where the file has none)."""
    group = next((g for g in bpy.data.node_groups
                  if g.bl_idname == 'ShaderNodeTree' and g.name.lower().startswith(GLTF_OUTPUT_GROUP.lower())), None)
    if group is None:
        group = bpy.data.node_groups.new(GLTF_OUTPUT_GROUP, 'ShaderNodeTree')
    inputs = {item.name for item in group.interface.items_tree
              if item.item_type == 'SOCKET' and item.in_out == 'INPUT'}
    if GLTF_OCCLUSION not in inputs:
        group.interface.new_socket(GLTF_OCCLUSION, in_out='INPUT', socket_type='NodeSocketFloat')
    return group


def wire_gltf_occlusion(tree: bpy.types.NodeTree, tex: bpy.types.Node) -> None:
    """Connect the AO image node to the Occlusion input of the material's glTF Material
    Output node (added once), so that glTF export writes it as occlusionTexture."""
    group = gltf_output_group()
    node = next((n for n in tree.nodes if n.bl_idname == 'ShaderNodeGroup' and n.node_tree == group), None)
    if node is None:
        node = tree.nodes.new('ShaderNodeGroup')
        node.node_tree = group
        node.label = GLTF_OUTPUT_GROUP
        node.location = (tex.location.x + 300, tex.location.y + 250)
    socket = node.inputs[GLTF_OCCLUSION]
    if not any(link.from_node == tex for link in socket.links):
        tree.links.new(tex.outputs["Color"], socket)


ORM_NODE_LABEL = "HAO ORM"


def wire_orm(obj: bpy.types.Object, image: bpy.types.Image, uv_name: str) -> None:
    """Wire an ORM texture (R occlusion, G roughness, B metallic; core/bake/orm.py) into the
    object's active material, as glTF export packs it: through a Separate Color node, R to the
    glTF Material Output's Occlusion, G to the Principled BSDF's Roughness, B to its Metallic
    (the exporter then writes one image as occlusionTexture and metallicRoughnessTexture).
    Call after wire_into_material (which made the material's AO nodes)."""
    tree = obj.active_material.node_tree
    tex = next((n for n in tree.nodes if n.bl_idname == 'ShaderNodeTexImage' and n.label == ORM_NODE_LABEL), None)
    if tex is None:
        tex = tree.nodes.new('ShaderNodeTexImage')
        tex.label = ORM_NODE_LABEL
        tex.location = (-700, -100)
        uv_node = tree.nodes.new('ShaderNodeUVMap')
        uv_node.location = (-900, -100)
        uv_node.uv_map = uv_name
        tree.links.new(uv_node.outputs["UV"], tex.inputs["Vector"])
    tex.image = image
    split = tree.nodes.new('ShaderNodeSeparateColor')
    split.location = (-450, -100)
    tree.links.new(tex.outputs["Color"], split.inputs[0])
    group = next(n for n in tree.nodes if n.bl_idname == 'ShaderNodeGroup' and n.node_tree == gltf_output_group())
    tree.links.new(split.outputs[0], group.inputs[GLTF_OCCLUSION])
    bsdf = next((n for n in tree.nodes if n.bl_idname == 'ShaderNodeBsdfPrincipled'), None)
    if bsdf is not None:
        tree.links.new(split.outputs[1], bsdf.inputs["Roughness"])
        tree.links.new(split.outputs[2], bsdf.inputs["Metallic"])


def store_map_image(pixels: np.ndarray, name: str, existing: bpy.types.Image | None = None) -> bpy.types.Image:
    """Put a baked map (row 0 = bottom) into a float image datablock, colour space Non-Color
    (AO and normals are data, not colour): (H, W) accessibility as grey RGB with alpha 1, or
    (H, W, 4) RGBA as it is (an encoded bent-normal map)."""
    h, w = pixels.shape[:2]
    image = existing
    if image is None:
        image = bpy.data.images.new(name, w, h, alpha=False, float_buffer=True)
    elif tuple(image.size) != (w, h) or not image.is_float:
        if image.source == 'GENERATED':
            # Generated images are resized through their generator settings (scale() leaves
            # an unloaded generated buffer at its old size).
            image.generated_width, image.generated_height = w, h
            image.use_generated_float = True
        else:
            image.scale(w, h)
    if len(image.pixels) != w * h * 4:
        raise RuntimeError(f"image '{image.name}' could not be resized to {w}x{h}")
    image.colorspace_settings.name = 'Non-Color'
    rgba = np.empty((h, w, 4), dtype=np.float32)
    if pixels.ndim == 3:
        rgba[...] = pixels
    else:
        rgba[..., :3] = pixels[..., None]
        rgba[..., 3] = 1.0
    image.pixels.foreach_set(rgba.ravel())
    image.update()
    return image


def store_tiled_image(maps: np.ndarray, tiles: tuple[int, ...], name: str,
                      existing: bpy.types.Image | None = None, tile_files: list[str] | None = None
                      ) -> bpy.types.Image:
    """A UDIM bake (maps (T, H, W) accessibility or (T, H, W, 4) RGBA, row 0 = bottom, one per
    UDIM number in tiles) as a tiled image datablock, Non-Color. The gpu-free Python API has no
    per-tile pixel access, so the image is loaded from the tiles' files: tile_files (the ones
    the bake saved, which the image then refers to), else 32-bit EXRs in a temporary folder,
    packed into the .blend and deleted. An existing image of that name is replaced, its users
    (material nodes) moved to the new one."""
    from ..core.bake.udim import tile_path
    from ..core.imageio import write_ao_file

    folder = None
    if tile_files is None:
        folder = tempfile.mkdtemp(prefix="hao-udim-")
        pattern = os.path.join(folder, f"{_file_stem(name)}.<UDIM>.exr")
        tile_files = [tile_path(pattern, tile) for tile in tiles]
        for path, tile_map in zip(tile_files, maps):
            write_ao_file(path, tile_map)
    try:
        image = bpy.data.images.load(tile_files[0], check_existing=False)
        image.source = 'TILED'  # finds the other tiles' files by the number in the name
        image.colorspace_settings.name = 'Non-Color'
        found = sorted(t.number for t in image.tiles)
        if found != sorted(tiles):
            bpy.data.images.remove(image)
            raise RuntimeError(f"the tiled image '{name}' found tiles {found}, expected {sorted(tiles)}")
        if folder is not None:
            image.pack()
    finally:
        if folder is not None:
            shutil.rmtree(folder, ignore_errors=True)
    if existing is not None:
        existing.user_remap(image)
        bpy.data.images.remove(existing)
    image.name = name
    return image


def _file_stem(name: str) -> str:
    return "".join(c if c.isalnum() or c in "-_" else "_" for c in name) or "map"


def image_pixels_gray(image: bpy.types.Image) -> np.ndarray:
    """(H, W) float32 red channel of an image datablock (row 0 = bottom)."""
    w, h = image.size
    px = np.empty(w * h * 4, dtype=np.float32)
    image.pixels.foreach_get(px)
    return px.reshape(h, w, 4)[..., 0]


def wire_into_material(obj: bpy.types.Object, image: bpy.types.Image, uv_name: str) -> bpy.types.Material:
    """Add an Image Texture node with the AO map (through a UV Map node) to the object's
    active material, make it the active node, multiply it into the Principled BSDF's Base
    Color once and connect it to the glTF Material Output's Occlusion (what glTF export
    writes as occlusionTexture). A material is created when the object has none."""
    mat = obj.active_material
    if mat is None:
        mat = bpy.data.materials.new(f"{obj.name}_HAO")
        obj.data.materials.append(mat)
    if mat.node_tree is None:  # materials made before 5.0 may lack a node tree
        mat.use_nodes = True
    tree = mat.node_tree
    tex = next((n for n in tree.nodes if n.bl_idname == 'ShaderNodeTexImage' and n.label == AO_NODE_LABEL), None)
    if tex is None:
        tex = tree.nodes.new('ShaderNodeTexImage')
        tex.label = AO_NODE_LABEL
        tex.location = (-700, 300)
        uv_node = tree.nodes.new('ShaderNodeUVMap')
        uv_node.location = (-900, 300)
        uv_node.uv_map = uv_name
        tree.links.new(uv_node.outputs["UV"], tex.inputs["Vector"])
    else:
        for link in tex.inputs["Vector"].links:
            if link.from_node.bl_idname == 'ShaderNodeUVMap':
                link.from_node.uv_map = uv_name
    tex.image = image
    tree.nodes.active = tex
    wire_gltf_occlusion(tree, tex)
    bsdf = next((n for n in tree.nodes if n.bl_idname == 'ShaderNodeBsdfPrincipled'), None)
    has_mix = any(n.label == AO_MIX_LABEL for n in tree.nodes)
    if bsdf is not None and not has_mix:
        base = bsdf.inputs["Base Color"]
        mix = tree.nodes.new('ShaderNodeMix')
        mix.label = AO_MIX_LABEL
        mix.data_type = 'RGBA'
        mix.blend_type = 'MULTIPLY'
        mix.location = (bsdf.location.x - 250, bsdf.location.y)
        mix.inputs[0].default_value = 1.0
        a_in, b_in = mix.inputs[6], mix.inputs[7]  # the colour A and B sockets
        if base.links:
            tree.links.new(base.links[0].from_socket, a_in)
        else:
            a_in.default_value = base.default_value
        tree.links.new(tex.outputs["Color"], b_in)
        tree.links.new(mix.outputs[2], base)
    return mat


# Image sources whose pixels come from a file on disk.
FILE_SOURCES = frozenset({'FILE', 'SEQUENCE', 'TILED', 'MOVIE'})


def scene_image_files() -> list[tuple[str, str]]:
    """The image files the open scene reads (alpha, roughness, metallic, any texture), as
    (absolute path, what) for the output check and the --skip-existing key: a bake must not
    write over a texture its materials read, and an edited texture makes its maps stale.
    Packed images live in the .blend (already an input); a file hao baked itself (its bake
    key in the metadata) is an output of an earlier bake, free to bake again."""
    from ..core.imageio import BAKE_KEY, read_text
    out = []
    for image in bpy.data.images:
        if image.source not in FILE_SOURCES or not image.filepath or image.packed_file is not None:
            continue
        path = os.path.normpath(bpy.path.abspath(image.filepath, library=image.library))
        if os.path.isfile(path) and read_text(path, BAKE_KEY) is not None:
            continue
        out.append((path, f"the image '{image.name}' that the scene's materials read"))
    return out
