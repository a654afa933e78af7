# SPDX-License-Identifier: GPL-3.0-or-later
"""glTF's occlusion-roughness-metallic texture (issue 30 item 5): R the AO, G and B the
material's roughness and metallic; wired into --gltf-out so that the exporter writes one
image as occlusionTexture and metallicRoughnessTexture, which the Khronos validator passes."""
from __future__ import annotations

import numpy as np

import bpy
from test_gltf import assert_valid_gltf, read_glb

STEP = 1.0 / 255.0


from bake_helpers import load_image_rgba as load_rgba  # noqa: E402


def test_cli_orm_out_packs_ao_roughness_metallic_and_the_glb_uses_it(tmp_path):
    from test_cli_runs import SPOT, run

    tmp = tmp_path / "tmp"
    tmp.mkdir()
    done = run(["bake", SPOT, "--size", "64", "--directions", "16", "--out", tmp_path / "ao.png", "--orm-out",
                tmp_path / "orm.png", "--gltf-out", tmp_path / "spot.glb", "--quiet"], tmp)
    assert done.returncode == 0, done.stderr
    ao, orm = load_rgba(tmp_path / "ao.png"), load_rgba(tmp_path / "orm.png")
    np.testing.assert_array_equal(orm[..., 0], ao[..., 0])  # R: the AO, both 16-bit
    inside = ao[..., 0] < 1.0
    # An OBJ has no material: the Principled BSDF's defaults, roughness 0.5, metallic 0.
    assert np.abs(orm[..., 1][inside] - 0.5).max() < 1e-4 and np.abs(orm[..., 2][inside]).max() < 1e-4
    glb = tmp_path / "spot.glb"
    assert_valid_gltf(glb)
    doc, binary = read_glb(glb)
    material = doc["materials"][0]
    texture = material["occlusionTexture"]["index"]
    assert material["pbrMetallicRoughness"]["metallicRoughnessTexture"]["index"] == texture  # one packed image
    view = doc["bufferViews"][doc["images"][doc["textures"][texture]["source"]]["bufferView"]]
    (tmp_path / "packed.png").write_bytes(binary[view.get("byteOffset", 0):view.get("byteOffset", 0) + view["byteLength"]])
    packed = load_rgba(tmp_path / "packed.png")  # 8-bit in the .glb
    np.testing.assert_allclose(packed[..., :3], orm[..., :3], atol=0.5 * STEP + 1e-4)


def test_material_images_and_values_fill_the_green_and_blue(scene, tmp_path):
    """Roughness from an image's green through Separate Color (as the glTF importer wires a
    metallicRoughness texture), metallic a value: G and B carry them texel for texel."""
    from conftest import select_only, soup_to_object
    from hao_addon.blender.bake_job import BakeJob
    from hao_addon.blender.bake_request import BakeRequest
    from hao_addon.core import scenes
    from hao_addon.core.bake.settings import BakeSettings

    obj = soup_to_object(scenes.grid_plane(2.0, 4), "tile")
    material = bpy.data.materials.new("tile")
    if bpy.app.version < (5, 0, 0):
        material.use_nodes = True
    nodes, links = material.node_tree.nodes, material.node_tree.links
    bsdf = next(n for n in nodes if n.type == 'BSDF_PRINCIPLED')
    bsdf.inputs['Metallic'].default_value = 0.8
    image = bpy.data.images.new("mr", 8, 8, float_buffer=True)
    image.colorspace_settings.name = 'Non-Color'  # before the pixels: a generated image is made anew on a change
    pixels = np.zeros((8, 8, 4), np.float32)
    pixels[..., 1] = np.linspace(0.0, 1.0, 8)[None, :]  # green runs with u
    pixels[..., 3] = 1.0
    image.pixels.foreach_set(pixels.ravel())
    texture = nodes.new('ShaderNodeTexImage')
    texture.image = image
    split = nodes.new('ShaderNodeSeparateColor')
    links.new(texture.outputs['Color'], split.inputs[0])
    links.new(split.outputs['Green'], bsdf.inputs['Roughness'])
    obj.data.materials.append(material)
    select_only(obj)
    request = BakeRequest([obj], BakeSettings(size=32, directions=8, margin=0), uv_map="UVMap",
                          filepath=str(tmp_path / "ao.exr"), map_paths={"orm": str(tmp_path / "orm.exr")})
    job = BakeJob(request, bpy.context.evaluated_depsgraph_get)
    job.run()
    job.commit()
    orm = load_rgba(tmp_path / "orm.exr")
    u = (np.arange(32) + 0.5) / 32
    expected_green = np.linspace(0.0, 1.0, 8)[np.minimum((u * 8).astype(int), 7)]
    np.testing.assert_allclose(orm[..., 1], np.tile(expected_green, (32, 1)), atol=1e-6)
    np.testing.assert_allclose(orm[..., 2], 0.8, atol=1e-6)


def test_orm_channels_past_the_margin_hold_their_mean_over_the_islands():
    """Before: 0 past the margin, so an ORM texture was pure red there (roughness 0, a mirror)
    and a mipmap's coarse levels blended it in."""
    from hao_addon.core.bake.orm import channel_map
    uvs = np.array([[[0.1, 0.1], [0.4, 0.1], [0.1, 0.4]], [[0.6, 0.6], [0.9, 0.6], [0.6, 0.9]]])
    values = channel_map(uvs, 64, lambda face, bary: np.where(face == 0, 0.2, 0.6), margin=2)
    inside = np.zeros((64, 64), bool)
    inside[np.isclose(values, 0.2) | np.isclose(values, 0.6)] = True
    corner, islands = values[63, 0], values[inside]
    assert abs(corner - islands.mean()) < 1e-6 and 0.2 < corner < 0.6
