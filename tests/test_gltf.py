# SPDX-License-Identifier: GPL-3.0-or-later
"""glTF occlusion (issue 13 item 5): Add to Material connects the map to the glTF Material
Output's Occlusion, so Blender's own glTF exporter writes it as the material's
occlusionTexture on the baked UV map. Checked by exporting a .glb and reading its JSON and
embedded PNG back."""
from __future__ import annotations

import json
import struct
from pathlib import Path

import numpy as np
import pytest

import bpy
from conftest import small_settings


VALIDATE = Path(__file__).resolve().parent.parent / "tools" / "gltf_validate.cjs"


def assert_valid_gltf(path) -> None:
    """The Khronos glTF Validator (tools/gltf_validate.cjs; installed by tools/setup.sh)
    finds no error in the file."""
    import subprocess
    done = subprocess.run(["node", str(VALIDATE), str(path)], capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, (done.stdout, done.stderr)
    report = json.loads(done.stdout.splitlines()[-1])
    assert report["errors"] == 0, report


def read_glb(path) -> tuple[dict, bytes]:
    """(JSON chunk, binary chunk) of a .glb file."""
    data = path.read_bytes()
    magic, _version, _length = struct.unpack_from("<4sII", data, 0)
    assert magic == b"glTF"
    json_len, json_type = struct.unpack_from("<I4s", data, 12)
    assert json_type == b"JSON"
    doc = json.loads(data[20:20 + json_len])
    bin_len, bin_type = struct.unpack_from("<I4s", data, 20 + json_len)
    assert bin_type == b"BIN\0"
    return doc, data[28 + json_len:28 + json_len + bin_len]


def occlusion_of(doc: dict, binary: bytes, tmp_path) -> tuple[np.ndarray, int, list[float]]:
    """(R channel (H, W) of the occlusion image, row 0 = bottom; its texCoord; the texture's
    first TEXCOORD set's first UV) of the first material."""
    occ = doc["materials"][0]["occlusionTexture"]
    image = doc["images"][doc["textures"][occ["index"]]["source"]]
    view = doc["bufferViews"][image["bufferView"]]
    png = tmp_path / "occlusion.png"
    png.write_bytes(binary[view.get("byteOffset", 0):view.get("byteOffset", 0) + view["byteLength"]])
    loaded = bpy.data.images.load(str(png))
    loaded.colorspace_settings.name = 'Non-Color'  # the file's values, not sRGB decoded to linear
    w, h = loaded.size
    px = np.empty(w * h * 4, np.float32)
    loaded.pixels.foreach_get(px)
    bpy.data.images.remove(loaded)
    return px.reshape(h, w, 4)[..., 0], occ.get("texCoord", 0), image.get("mimeType")


@pytest.mark.parametrize("uv_maps", [["UVMap"], ["Other", "Baked"], []])
def test_exported_glb_carries_the_baked_map_as_occlusion(scene, tmp_path, uv_maps):
    """A mesh with one UV map, one baked into its second map (texCoord 1), and one without
    UVs that xatlas unwraps (AO_UV)."""
    bpy.ops.mesh.primitive_monkey_add()  # comes with the UV map "UVMap"
    obj = bpy.context.active_object
    mesh = obj.data
    if not uv_maps:
        mesh.uv_layers.remove(mesh.uv_layers[0])
    elif len(uv_maps) == 2:  # a second map with its own layout, so texCoord tells them apart
        mesh.uv_layers[0].name = uv_maps[0]
        mesh.uv_layers.active = mesh.uv_layers.new(name=uv_maps[1])
        bpy.ops.object.mode_set(mode='EDIT')
        bpy.ops.mesh.select_all(action='SELECT')
        bpy.ops.uv.smart_project(island_margin=0.02)
        bpy.ops.object.mode_set(mode='OBJECT')
    settings = small_settings(scene, wire_material=True, directions=32, size=64)
    if uv_maps:
        settings.uv_mode, settings.uv_map = 'NAMED', uv_maps[-1]
    bpy.ops.object.hao_bake_ao()
    baked_uv = uv_maps[-1] if uv_maps else "AO_UV"
    image = bpy.data.images[f"{obj.name}_AO"]
    ao = np.empty(64 * 64 * 4, np.float32)
    image.pixels.foreach_get(ao)
    ao = ao.reshape(64, 64, 4)[..., 0]
    path = tmp_path / "baked.glb"
    assert bpy.ops.export_scene.gltf(filepath=str(path), export_format='GLB', use_selection=True) == {'FINISHED'}
    assert_valid_gltf(path)
    doc, binary = read_glb(path)
    red, tex_coord, mime = occlusion_of(doc, binary, tmp_path)
    order = [layer.name for layer in mesh.uv_layers]
    assert tex_coord == order.index(baked_uv), (tex_coord, order)
    assert mime == "image/png" and red.shape == ao.shape
    # 8-bit PNG of the float map: within half a step, and not a constant.
    np.testing.assert_allclose(red, ao, atol=0.5 / 255 + 1e-4)
    assert ao.min() < 0.5 < ao.max()


def test_cli_gltf_out_writes_the_asset_with_its_occlusion(tmp_path):
    """--gltf-out: the baked object as a .glb whose occlusionTexture is the map written to
    --out (16-bit PNG there, 8-bit in the .glb); a non-.glb name is refused before any work."""
    from test_cli_runs import SPOT, run

    tmp = tmp_path / "tmp"
    tmp.mkdir()
    out, glb = tmp_path / "ao.png", tmp_path / "spot.glb"
    proc = run(["bake", SPOT, "--size", "64", "--directions", "16", "--out", out, "--gltf-out", glb, "--quiet"], tmp)
    assert proc.returncode == 0, proc.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["ao.png", "spot.glb", "tmp"]  # no temporary left
    assert_valid_gltf(glb)
    doc, binary = read_glb(glb)
    red, tex_coord, _mime = occlusion_of(doc, binary, tmp_path)
    written = bpy.data.images.load(str(out))
    written.colorspace_settings.name = 'Non-Color'
    px = np.empty(64 * 64 * 4, np.float32)
    written.pixels.foreach_get(px)
    bpy.data.images.remove(written)
    assert tex_coord == 0
    np.testing.assert_allclose(red, px.reshape(64, 64, 4)[..., 0], atol=0.5 / 255 + 1e-4)
    proc = run(["bake", SPOT, "--size", "64", "--out", tmp_path / "b.png", "--gltf-out", tmp_path / "x.gltf"], tmp)
    assert proc.returncode == 2 and "--gltf-out must be a .glb" in proc.stderr
    assert not (tmp_path / "b.png").exists()
