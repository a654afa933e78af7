# SPDX-License-Identifier: GPL-3.0-or-later
"""Texture sets (issue 13 item 4): several objects, each with its own UVs, bake into one
shared image; each occludes the others; islands that overlap across objects are refused with
a message naming them."""
from __future__ import annotations

import numpy as np
import pytest

import bpy
from conftest import run_hao, select_only, small_settings, soup_to_object
from hao_addon.bake import bake
from hao_addon.blender import mesh_data
from hao_addon.core import scenes
from hao_addon.core.bake.settings import BakeSettings
from hao_addon.core.bake.texture_set import cross_object_overlaps, texture_set_target
from hao_addon.core.errors import BakeInputError
from hao_addon.core.geometry import TriangleSoup


def placed(soup: TriangleSoup, lo, hi) -> TriangleSoup:
    """The soup with its 0..1 UVs moved into the box lo..hi of the shared image."""
    return TriangleSoup(soup.positions, np.asarray(lo) + soup.uvs * (np.asarray(hi) - np.asarray(lo)), soup.name,
                        soup.normals)


def parts() -> list[TriangleSoup]:
    return [placed(scenes.uv_sphere(0.5, (0, 0, 0.5), 32, 16, name="ball"), (0.02, 0.02), (0.48, 0.98)),
            placed(scenes.grid_plane(4.0, 8, name="floor"), (0.52, 0.02), (0.98, 0.98))]


def test_overlap_across_objects_is_refused_naming_them():
    ball, floor = parts()
    assert cross_object_overlaps([ball, floor], 512) == []
    moved = placed(scenes.grid_plane(4.0, 8, name="floor"), (0.3, 0.02), (0.98, 0.98))
    [(a, b, fraction)] = cross_object_overlaps([ball, moved], 512)
    assert (a, b) == ("ball", "floor") and fraction > 0.2
    with pytest.raises(BakeInputError, match="'ball' and 'floor'"):
        texture_set_target([ball, moved], 512)


def test_shared_image_holds_each_object_as_its_own_bake_with_the_others_occluding(gpu_context):
    """The set's map equals, on each object's texels, that object's bake with the other as
    occluder (the reference: the same receivers and directions, equal to float rounding)."""
    ball, floor = parts()
    settings = BakeSettings(size=64, directions=64, method="reference", margin=0, normals="face")
    shared = bake(texture_set_target([ball, floor], 64), [], settings, use_cache=False)
    for own, other in ((ball, floor), (floor, ball)):
        alone = bake(own, [other], settings, use_cache=False)
        mask = alone.covered
        np.testing.assert_allclose(shared.ao[mask], alone.ao[mask], atol=1e-5)
    assert shared.covered.sum() == sum(bake(p, [], settings, use_cache=False).covered.sum() for p in (ball, floor))


def test_operator_bakes_the_selection_into_one_image(scene, tmp_path):
    """Texture Set: one image 'TextureSet_AO' and one file, both materials show it; a set
    whose islands overlap is refused naming the objects, and nothing changes."""
    ball, floor = (soup_to_object(p) for p in parts())
    select_only(ball, floor)
    small_settings(scene, texture_set=True, wire_material=True, filepath=str(tmp_path / "{object}.png"))
    assert bpy.ops.object.hao_bake_ao() == {'FINISHED'}
    image = bpy.data.images["TextureSet_AO"]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["TextureSet.png"]
    for obj in (ball, floor):
        node = next(n for n in obj.active_material.node_tree.nodes if n.bl_idname == 'ShaderNodeTexImage')
        assert node.image == image
    assert not any(i.name.startswith(("ball", "floor")) for i in bpy.data.images)
    depsgraph = bpy.context.evaluated_depsgraph_get()
    soups = [mesh_data.evaluated_soup(o, depsgraph, "UVMap") for o in (ball, floor)]
    core = bake(texture_set_target(soups, 128), [], scene.hao_bake.to_settings())
    pixels = np.empty(128 * 128 * 4, np.float32)
    image.pixels.foreach_get(pixels)
    np.testing.assert_allclose(pixels.reshape(128, 128, 4)[..., 0], core.ao, atol=1e-6)
    # Overlapping islands: refused before anything is made.
    uv = floor.data.uv_layers[0].uv
    coords = np.empty(len(uv) * 2, np.float32)
    uv.foreach_get("vector", coords)
    uv.foreach_set("vector", coords - np.tile([0.5, 0.0], len(uv)).astype(np.float32))
    before = len(bpy.data.images)
    with pytest.raises(RuntimeError, match="'ball' and 'floor'"):
        bpy.ops.object.hao_bake_ao()
    assert len(bpy.data.images) == before


def test_cli_texture_set_and_several_objects(tmp_path):
    """--object twice with --texture-set: one file named after the set, both objects in the
    report; without it, one file per object ({object})."""
    import json
    import os
    from test_cli_runs import write_obj
    source = tmp_path / "set.obj"
    write_obj(source, {p.name: p for p in parts()})
    out = tmp_path / "out"
    out.mkdir()

    def run(*extra):
        return run_hao(["bake", source, "--size", "64", "--directions", "16", "--object", "ball", "--object", "floor",
                        "--json", tmp_path / "r.json", *extra], cwd=tmp_path, timeout=300)
    done = run("--texture-set", "--out", out / "{object}.png")
    assert done.returncode == 0, done.stderr
    report = json.loads((tmp_path / "r.json").read_text())
    assert [o["name"] for o in report["objects"]] == ["ball", "floor"] and report["objects"][0]["texture_set"]
    assert report["outputs"] == [str(out / "TextureSet.png")] and sorted(os.listdir(out)) == ["TextureSet.png"]
    os.unlink(out / "TextureSet.png")
    done = run("--out", out / "{object}.png")
    assert done.returncode == 0, done.stderr
    assert sorted(os.listdir(out)) == ["ball.png", "floor.png"] and done.stdout.count("hao: baked") == 2
