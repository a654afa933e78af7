# SPDX-License-Identifier: GPL-3.0-or-later
"""AO maps as Blender image datablocks, and wiring them into materials."""
from __future__ import annotations

import os
import shutil
import tempfile

import bpy
import numpy as np

AO_NODE_LABEL = "HAO AO"  # the AO image node's label (and the frame of the AO nodes)
AO_MIX_LABEL = "HAO AO Multiply"
ORM_NODE_LABEL = "HAO ORM"
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


def _named_node(tree: bpy.types.NodeTree, bl_idname: str, name: str, frame: bpy.types.Node | None,
                location: tuple[float, float], label: str = "") -> bpy.types.Node:
    """The node called name (or, from an earlier release, labelled so), else a new one of that
    type with that name, label and location, inside frame: an artist sees which nodes are ours,
    and a bake again reuses them instead of stacking more."""
    node = tree.nodes.get(name)
    if node is None or node.bl_idname != bl_idname:
        node = next((n for n in tree.nodes if n.bl_idname == bl_idname and n.label == (label or name)), None)
    if node is None:
        node = tree.nodes.new(bl_idname)
        node.location = location
    node.name, node.label = name, label or name
    if frame is not None and node.parent is None:
        node.parent = frame
    return node


def _image_nodes(tree: bpy.types.NodeTree, prefix: str, image: bpy.types.Image, uv_name: str,
                 y: float) -> tuple[bpy.types.Node, bpy.types.Node]:
    """(frame, image node) of one map: a frame '<prefix>' holding an Image Texture node
    '<prefix> Image' labelled prefix, fed by a UV Map node '<prefix> UV Map' on uv_name."""
    frame = _named_node(tree, 'NodeFrame', prefix, None, (-950, y + 120))
    tex = _named_node(tree, 'ShaderNodeTexImage', f"{prefix} Image", frame, (-700, y), label=prefix)
    uv_node = _named_node(tree, 'ShaderNodeUVMap', f"{prefix} UV Map", frame, (-900, y))
    uv_node.uv_map = uv_name
    if not any(link.from_node == uv_node for link in tex.inputs["Vector"].links):
        tree.links.new(uv_node.outputs["UV"], tex.inputs["Vector"])
    tex.image = image
    return frame, tex


def wire_gltf_occlusion(tree: bpy.types.NodeTree, socket: bpy.types.NodeSocket, frame: bpy.types.Node) -> None:
    """Connect socket (the AO image's colour, or an ORM's red) to the Occlusion input of the
    material's glTF Material Output node (one made, named 'HAO AO glTF Material Output', where
    the material has none), so that glTF export writes it as occlusionTexture and renders
    are not darkened by it."""
    group = gltf_output_group()
    node = next((n for n in tree.nodes if n.bl_idname == 'ShaderNodeGroup' and n.node_tree == group), None)
    if node is None:
        node = _named_node(tree, 'ShaderNodeGroup', f"{AO_NODE_LABEL} {GLTF_OUTPUT_GROUP}", frame, (-400, 420),
                           label=GLTF_OUTPUT_GROUP)
        node.node_tree = group
    target = node.inputs[GLTF_OCCLUSION]
    if not any(link.from_socket == socket for link in target.links):
        tree.links.new(socket, target)


def wire_into_material(obj: bpy.types.Object, image: bpy.types.Image, uv_name: str,
                       multiply_base_color: bool = False) -> bpy.types.Material:
    """Add the AO map to the object's active material the way Blender's glTF exporter reads
    it: an Image Texture node 'HAO AO Image' (the active node, through a UV Map node) into the
    glTF Material Output's Occlusion socket, in a frame 'HAO AO'. Renders do not darken twice
    (Cycles and EEVEE compute their own AO); multiply_base_color also multiplies it into the
    Principled BSDF's Base Color once ('HAO AO Multiply'), and without it a multiply an earlier
    bake added is taken out again. A material is created when the object has none."""
    mat = obj.active_material
    if mat is None:
        mat = bpy.data.materials.new(f"{obj.name}_HAO")
        obj.data.materials.append(mat)
    if mat.node_tree is None:  # materials made before 5.0 may lack a node tree
        mat.use_nodes = True
    tree = mat.node_tree
    frame, tex = _image_nodes(tree, AO_NODE_LABEL, image, uv_name, 300)
    tree.nodes.active = tex
    wire_gltf_occlusion(tree, tex.outputs["Color"], frame)
    bsdf = next((n for n in tree.nodes if n.bl_idname == 'ShaderNodeBsdfPrincipled'), None)
    if bsdf is not None and multiply_base_color:
        _multiply_into(tree, bsdf.inputs["Base Color"], tex, frame)
    elif bsdf is not None:
        _take_out_multiply(tree, bsdf.inputs["Base Color"])
    return mat


def _multiply_into(tree, base: bpy.types.NodeSocket, tex: bpy.types.Node, frame: bpy.types.Node) -> None:
    """Base Color = (what fed it) x AO, through one Mix node 'HAO AO Multiply'."""
    if base.links and base.links[0].from_node.label == AO_MIX_LABEL:
        return
    mix = _named_node(tree, 'ShaderNodeMix', AO_MIX_LABEL, frame, (-400, 250))
    mix.data_type = 'RGBA'
    mix.blend_type = 'MULTIPLY'
    mix.inputs[0].default_value = 1.0
    a_in, b_in = mix.inputs[6], mix.inputs[7]  # the colour A and B sockets
    if base.links:
        tree.links.new(base.links[0].from_socket, a_in)
    else:
        a_in.default_value = base.default_value
    tree.links.new(tex.outputs["Color"], b_in)
    tree.links.new(mix.outputs[2], base)


def _take_out_multiply(tree, base: bpy.types.NodeSocket) -> None:
    """Undo _multiply_into: Base Color fed again by what fed the Multiply's A (or its value)."""
    mix = next((n for n in tree.nodes if n.bl_idname == 'ShaderNodeMix' and n.label == AO_MIX_LABEL), None)
    if mix is None:
        return
    a_in = mix.inputs[6]
    if base.links and base.links[0].from_node == mix:
        if a_in.links:
            tree.links.new(a_in.links[0].from_socket, base)
        else:
            tree.links.remove(base.links[0])
            base.default_value = a_in.default_value
    tree.nodes.remove(mix)


def wire_orm(obj: bpy.types.Object, image: bpy.types.Image, uv_name: str) -> None:
    """Wire an ORM texture (R occlusion, G roughness, B metallic; core/bake/orm.py) into the
    object's active material, as glTF export packs it: in a frame 'HAO ORM', through a
    Separate Color node, R to the glTF Material Output's Occlusion, G to the Principled BSDF's
    Roughness, B to its Metallic (the exporter then writes one image as occlusionTexture and
    metallicRoughnessTexture). Call after wire_into_material (which made the material's AO nodes)."""
    tree = obj.active_material.node_tree
    frame, tex = _image_nodes(tree, ORM_NODE_LABEL, image, uv_name, -100)
    split = _named_node(tree, 'ShaderNodeSeparateColor', f"{ORM_NODE_LABEL} Separate Color", frame, (-450, -100))
    if not split.inputs[0].links:
        tree.links.new(tex.outputs["Color"], split.inputs[0])
    wire_gltf_occlusion(tree, split.outputs[0], frame)
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
