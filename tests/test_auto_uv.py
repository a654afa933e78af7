# SPDX-License-Identifier: GPL-3.0-or-later
"""A mesh without UVs always gets a map a bake can use (blender/auto_uv.py): Suzanne, whose
quads the fast unwrap split across charts (its UVs as Blender wrote them overlapped on
0.5-1.2 %: nothing baked), and xatlas' own charts where the fast unwrap still overlaps."""
from __future__ import annotations

import pytest

import bpy
from conftest import DATA, select_only, small_settings, soup_to_object
from hao_addon.blender import auto_uv, mesh_data
from hao_addon.core import scenes
from hao_addon.core.bake.charts import overlapping_texels
from hao_addon.core.steps import drain


def _bake(scene, obj, size: int):
    from hao_addon.blender.bake_job import BakeJob
    select_only(obj)
    settings = small_settings(scene, directions=4, size=size, margin=0, method='gather')
    job = BakeJob(settings.to_request([obj]), bpy.context.evaluated_depsgraph_get)
    job.run()
    return job


@pytest.mark.parametrize("size", [512, 1024])
def test_suzanne_without_uvs_unwraps_without_overlap(scene, size):
    bpy.ops.wm.obj_import(filepath=str(DATA / "suzanne.obj"))
    suzanne = bpy.context.selected_objects[0]
    assert not suzanne.data.uv_layers and len(suzanne.data.polygons) == 500
    job = _bake(scene, suzanne, size)
    assert job.results[0][1] == mesh_data.AO_UV_NAME and not job.unwrap_notes
    _positions, _tris, tri_loops, _polygons = mesh_data.base_mesh_triangles(suzanne)
    written = mesh_data.written_triangle_uvs(suzanne.data, mesh_data.AO_UV_NAME, tri_loops)
    assert overlapping_texels(written, size)[0] == 0


def test_an_overlapping_fast_unwrap_falls_back_to_xatlas_and_says_so(scene, monkeypatch):
    torus = soup_to_object(scenes.torus(1.0, 0.3, (0.0, 0.0, 0.0), 24, 12), "torus", uv=False)
    checks = []

    def first_overlaps(written, size, name="mesh"):
        checks.append(len(checks))
        if len(checks) == 1:
            raise auto_uv.UnwrapError(f"the automatic UVs of '{name}' overlap on 1 of 2 texels")
        return real(written, size, name)

    real = auto_uv.check_unwrap_overlap
    monkeypatch.setattr(auto_uv, "check_unwrap_overlap", first_overlaps)
    job = _bake(scene, torus, 256)
    assert len(checks) == 2 and job.unwrap_notes == ["'torus': the fast unwrap overlapped; unwrapped with xatlas' "
                                                     "own charts"]
    assert list(torus.data.uv_layers.keys()) == [mesh_data.AO_UV_NAME]  # the first map was removed
    assert job.results[0][2].covered.sum() > 0.3 * 256 * 256


MESHES = ["suzanne.obj", "spot.obj", "fandisk.obj", "rocker-arm.obj", "CesiumMan.glb",
          "../../bench/data/stanford-bunny.obj"]


@pytest.mark.parametrize("name, size", [(name, 256) for name in MESHES] + [(MESHES[0], 4096), (MESHES[-1], 4096)])
def test_every_mesh_of_the_repository_unwraps_without_overlap_as_written(scene, name, size):
    """Each mesh here without its UVs (those of ../shared/meshes, copied), written into a UV
    map as a bake reads it back. All of them came out without overlap at 256^2, 1024^2 and
    4096^2 (at 4096^2 10-15 s each: only Suzanne, which overlapped before, and the bunny, the
    largest, are tested there)."""
    path = DATA / name
    if path.suffix == ".glb":
        bpy.ops.import_scene.gltf(filepath=str(path))
    else:
        bpy.ops.wm.obj_import(filepath=str(path))
    for obj in [o for o in bpy.context.scene.objects if o.type == 'MESH']:
        while obj.data.uv_layers:
            obj.data.uv_layers.remove(obj.data.uv_layers[0])
        created = []
        uv_name, note = drain(auto_uv.unwrapped_steps(obj, size, created))
        assert uv_name == mesh_data.AO_UV_NAME and note == "" and created == [(obj.data, uv_name)]
        _positions, _tris, tri_loops, _polygons = mesh_data.base_mesh_triangles(obj)
        overlap, covered = overlapping_texels(mesh_data.written_triangle_uvs(obj.data, uv_name, tri_loops), size)
        assert overlap == 0 and covered > 0.3 * size * size, (obj.name, overlap, covered)
