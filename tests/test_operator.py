# SPDX-License-Identifier: GPL-3.0-or-later
"""The Bake AO operator on real Blender data: images, UV maps, materials, files, cancel, undo."""
from __future__ import annotations

import numpy as np
import pytest

import bpy
from conftest import DATA, select_only, small_settings, soup_to_object
from hao_addon.core import scenes
from hao_addon.gpu.util import live_pass_count, snapshot_state


def uv_array(mesh, name):
    a = np.empty(len(mesh.loops) * 2, np.float32)
    mesh.uv_layers[name].uv.foreach_get("vector", a)
    return a


def monkey():
    bpy.ops.mesh.primitive_monkey_add()
    obj = bpy.context.active_object
    return obj


def test_poll_explains_why_it_is_greyed_out(scene):
    select_only()
    assert not bpy.ops.object.hao_bake_ao.poll()
    with pytest.raises(RuntimeError, match="Select one or more mesh objects"):
        bpy.ops.object.hao_bake_ao()


def test_bake_creates_float_non_color_image_and_keeps_uvs(scene):
    obj = monkey()
    before = uv_array(obj.data, "UVMap")
    small_settings(scene)
    assert bpy.ops.object.hao_bake_ao() == {'FINISHED'}
    image = bpy.data.images[f"{obj.name}_AO"]
    assert image.is_float and image.colorspace_settings.name == 'Non-Color'
    assert tuple(image.size) == (128, 128)
    px = np.empty(128 * 128 * 4, np.float32)
    image.pixels.foreach_get(px)
    gray = px.reshape(128, 128, 4)[..., 0]
    assert np.isfinite(gray).all() and gray.min() >= 0 and gray.max() <= 1
    assert gray.min() < 0.5 < gray.max()  # the monkey has deep creases and open surfaces
    np.testing.assert_array_equal(uv_array(obj.data, "UVMap"), before)
    assert [l.name for l in obj.data.uv_layers] == ["UVMap"]


def test_mesh_without_uvs_gets_ao_uv_from_xatlas(scene):
    obj = monkey()
    obj.data.uv_layers.remove(obj.data.uv_layers[0])
    small_settings(scene, uv_mode='AUTO')
    assert bpy.ops.object.hao_bake_ao() == {'FINISHED'}
    assert [l.name for l in obj.data.uv_layers] == ["AO_UV"]
    uv = uv_array(obj.data, "AO_UV").reshape(-1, 2)
    assert uv.min() >= 0 and uv.max() <= 1 and np.ptp(uv, axis=0).min() > 0.5
    assert written_overlap(obj, "AO_UV", 128) == 0  # issue 38: a quad per chart, not half of one
    # A second bake reuses AO_UV instead of unwrapping again.
    bpy.ops.object.hao_bake_ao()
    assert [l.name for l in obj.data.uv_layers] == ["AO_UV"]


def written_overlap(obj, uv_name: str, size: int) -> int:
    """Texel centres of a size^2 map inside two triangles of the UV map as Blender stores
    it (per polygon corner): what a bake into it writes twice."""
    from hao_addon.blender.mesh_data import base_mesh_triangles, written_triangle_uvs
    from hao_addon.core.bake.charts import overlapping_texels
    _co, _tris, loops, _polygons = base_mesh_triangles(obj)
    return overlapping_texels(written_triangle_uvs(obj.data, uv_name, loops), size)[0]


def _subdivided(obj, levels=1):
    modifier = obj.modifiers.new("Subdivision", 'SUBSURF')
    modifier.levels = levels
    with bpy.context.temp_override(object=obj, active_object=obj):
        bpy.ops.object.modifier_apply(modifier=modifier.name)
    return obj


def _without_uvs(obj):
    while obj.data.uv_layers:
        obj.data.uv_layers.remove(obj.data.uv_layers[0])
    return obj


def _added(op, **kw):
    op(**kw)
    return bpy.context.active_object


def _imported(path):
    before = set(bpy.data.objects)
    if path.suffix == ".glb":
        bpy.ops.import_scene.gltf(filepath=str(path))
    else:
        bpy.ops.wm.obj_import(filepath=str(path))
    return max((o for o in bpy.data.objects if o not in before and o.type == 'MESH'), key=lambda o: len(o.data.polygons))


# Meshes as Blender users have them, without UVs (issue 38): quads, quads subdivided,
# n-gons (a cylinder's caps), a skinned character and a CAD part.
UNWRAP_MESHES = {
    "suzanne-quads": lambda: _added(bpy.ops.mesh.primitive_monkey_add),
    "suzanne-subdivided": lambda: _subdivided(_added(bpy.ops.mesh.primitive_monkey_add)),
    "cube-subdivided": lambda: _subdivided(_added(bpy.ops.mesh.primitive_cube_add)),
    "cylinder-ngons": lambda: _added(bpy.ops.mesh.primitive_cylinder_add, vertices=24),
    "cesium-man": lambda: _imported(DATA / "CesiumMan.glb"),
    "fandisk": lambda: _imported(DATA / "fandisk.obj"),
}


@pytest.mark.parametrize("name", UNWRAP_MESHES)
def test_auto_unwrap_writes_uvs_that_overlap_nowhere(scene, name):
    """Measured on the UV map as written (per polygon corner) at texel centres: 0 texels
    written twice. Before, a quad's two triangles could land in two charts: Suzanne
    overlapped on half its texels, with exit 0."""
    obj = _without_uvs(UNWRAP_MESHES[name]())
    select_only(obj)
    small_settings(scene, uv_mode='AUTO', size=256, directions=8)
    assert bpy.ops.object.hao_bake_ao() == {'FINISHED'}
    assert "AO_UV" in obj.data.uv_layers
    assert written_overlap(obj, "AO_UV", 256) == 0


def test_overlapping_written_uvs_fail_the_bake_and_leave_no_uv_map(scene, monkeypatch, addon):
    """The rule behind it: a map the tool itself sees is wrong is a failure. Triangles
    unwrapped one by one (the old way) overlap on Suzanne, and so do xatlas' own charts, the
    fallback, which split quads too: the bake stops, nothing stays."""
    import sys
    auto_uv = sys.modules[f"{addon.__name__}.hao_addon.blender.auto_uv"]  # the operator's copy
    real = auto_uv.unwrap_steps
    monkeypatch.setattr(auto_uv, "unwrap_steps", lambda *a, polygons=None, **kw: real(*a, **kw))
    obj = _without_uvs(_added(bpy.ops.mesh.primitive_monkey_add))
    select_only(obj)
    small_settings(scene, uv_mode='AUTO', size=256, directions=8)
    images = set(bpy.data.images.keys())
    with pytest.raises(RuntimeError, match=r"the automatic UVs of 'Suzanne' overlap on \d+ of \d+ texels"):
        bpy.ops.object.hao_bake_ao()
    assert len(obj.data.uv_layers) == 0 and set(bpy.data.images.keys()) == images


def test_named_uv_map_missing_is_a_clear_error(scene):
    monkey()
    small_settings(scene, uv_mode='NAMED', uv_map="Nope")
    with pytest.raises(RuntimeError, match="no UV map named 'Nope'") as raised:
        bpy.ops.object.hao_bake_ao()
    assert "internal error" not in str(raised.value)  # the user's mistake, said as such


def test_a_bug_is_reported_as_an_internal_error_and_changes_nothing(scene, monkeypatch, addon):
    """Only the project's own error types are the user's (operators/bake_operator.USER_ERRORS):
    a KeyError inside the bake is a bug, reported as an internal error that says where its
    traceback went, not as bad input; the scene is as it was."""
    import sys
    bake_job = sys.modules[f"{addon.__name__}.hao_addon.blender.bake_job"]  # the operator's copy

    def broken(self):
        raise KeyError("a bug")

    monkeypatch.setattr(bake_job.BakeJob, "run", broken)
    obj = monkey()
    before, images = uv_array(obj.data, "UVMap"), set(bpy.data.images.keys())
    small_settings(scene)
    with pytest.raises(RuntimeError, match=r"internal error \(KeyError: 'a bug'\); the traceback is in the system "
                                           r"console"):
        bpy.ops.object.hao_bake_ao()
    assert set(bpy.data.images.keys()) == images and [l.name for l in obj.data.uv_layers] == ["UVMap"]
    np.testing.assert_array_equal(uv_array(obj.data, "UVMap"), before)


def test_existing_image_is_overwritten_and_material_wired(scene):
    obj = monkey()
    target = bpy.data.images.new("Mine", 64, 64, float_buffer=True)
    small_settings(scene, image=target, wire_material=True)
    assert bpy.ops.object.hao_bake_ao() == {'FINISHED'}
    assert tuple(target.size) == (128, 128) and f"{obj.name}_AO" not in bpy.data.images
    mat = obj.active_material
    tex = [n for n in mat.node_tree.nodes if n.bl_idname == 'ShaderNodeTexImage']
    assert len(tex) == 1 and tex[0].image == target and mat.node_tree.nodes.active == tex[0]
    uvnode = tex[0].inputs["Vector"].links[0].from_node
    assert uvnode.uv_map == "UVMap"
    bsdf = next(n for n in mat.node_tree.nodes if n.bl_idname == 'ShaderNodeBsdfPrincipled')
    assert not bsdf.inputs["Base Color"].links  # the glTF Occlusion socket only: renders do not darken twice
    # Baking again does not stack more nodes.
    n_nodes = len(mat.node_tree.nodes)
    bpy.ops.object.hao_bake_ao()
    assert len(mat.node_tree.nodes) == n_nodes


def test_add_to_material_feeds_gltf_occlusion_and_multiplies_only_when_asked(scene):
    """Add to Material wires the AO as Blender's glTF exporter reads it (the glTF Material
    Output's Occlusion), not into Base Color; every node it adds is named 'HAO AO ...' and sits
    in the frame 'HAO AO'. Multiply into Base Color is the explicit choice, and a bake without
    it takes an earlier multiply out, restoring what fed Base Color."""
    obj = monkey()
    mat = bpy.data.materials.new("Painted")
    obj.data.materials.append(mat)
    if mat.node_tree is None:  # before 5.0 a new material has no node tree
        mat.use_nodes = True
    tree = mat.node_tree
    bsdf = next(n for n in tree.nodes if n.bl_idname == 'ShaderNodeBsdfPrincipled')
    paint = tree.nodes.new('ShaderNodeRGB')
    tree.links.new(paint.outputs[0], bsdf.inputs["Base Color"])
    before = set(tree.nodes)
    small_settings(scene, wire_material=True)
    assert bpy.ops.object.hao_bake_ao() == {'FINISHED'}
    added = set(tree.nodes) - before
    assert sorted(n.name for n in added) == ["HAO AO", "HAO AO Image", "HAO AO UV Map",
                                             "HAO AO glTF Material Output"]
    frame = tree.nodes["HAO AO"]
    assert frame.bl_idname == 'NodeFrame' and all(n.parent == frame for n in added - {frame})
    occlusion = tree.nodes["HAO AO glTF Material Output"].inputs["Occlusion"]
    assert occlusion.links[0].from_node == tree.nodes["HAO AO Image"]
    assert bsdf.inputs["Base Color"].links[0].from_node == paint
    settings = scene.hao_bake
    settings.multiply_base_color = True
    assert bpy.ops.object.hao_bake_ao() == {'FINISHED'}
    mix = bsdf.inputs["Base Color"].links[0].from_node
    assert mix.name == "HAO AO Multiply" and mix.parent == frame and mix.inputs[6].links[0].from_node == paint
    assert mix.inputs[7].links[0].from_node == tree.nodes["HAO AO Image"]
    settings.multiply_base_color = False
    assert bpy.ops.object.hao_bake_ao() == {'FINISHED'}
    assert "HAO AO Multiply" not in tree.nodes and bsdf.inputs["Base Color"].links[0].from_node == paint
    assert set(tree.nodes) - before == added


@pytest.mark.parametrize("ext", ["png", "exr"])
def test_saved_file_matches_image_and_orientation(scene, tmp_path, ext):
    obj = monkey()
    path = tmp_path / f"ao.{ext}"
    small_settings(scene, filepath=str(path))
    bpy.ops.object.hao_bake_ao()
    baked = bpy.data.images[f"{obj.name}_AO"]
    ref = np.empty(128 * 128 * 4, np.float32)
    baked.pixels.foreach_get(ref)
    loaded = bpy.data.images.load(str(path))
    loaded.colorspace_settings.name = 'Non-Color'
    got = np.empty(128 * 128 * 4, np.float32)
    loaded.pixels.foreach_get(got)
    # Blender reads both files bottom-up like its own pixels: same orientation, same values.
    tol = 1.0 / 65535 + 1e-6 if ext == "png" else 1e-7
    np.testing.assert_allclose(got.reshape(128, 128, 4)[..., 0], ref.reshape(128, 128, 4)[..., 0], atol=tol)
    assert not list(tmp_path.glob("*.part"))


def test_unwritable_output_fails_before_anything_changes(scene, tmp_path):
    obj = monkey()
    (tmp_path / "file").write_bytes(b"")
    small_settings(scene, filepath=str(tmp_path / "file" / "missing" / "ao.png"))
    with pytest.raises(RuntimeError, match="is a file, not a folder"):
        bpy.ops.object.hao_bake_ao()
    small_settings(scene, filepath=str(tmp_path / "ao.jpg"))
    with pytest.raises(RuntimeError, match="unsupported output extension"):
        bpy.ops.object.hao_bake_ao()
    assert f"{obj.name}_AO" not in bpy.data.images


def test_nan_vertices_and_empty_mesh_are_reported(scene):
    obj = monkey()
    obj.data.vertices[0].co = (float("nan"), 0.0, 0.0)
    small_settings(scene)
    with pytest.raises(RuntimeError, match="NaN"):
        bpy.ops.object.hao_bake_ao()
    empty = bpy.data.objects.new("Empty", bpy.data.meshes.new("Empty"))
    scene.collection.objects.link(empty)
    select_only(empty)
    with pytest.raises(RuntimeError, match="no faces"):
        bpy.ops.object.hao_bake_ao()
    assert not [i for i in bpy.data.images if i.name.endswith("_AO")]


def test_cancel_leaves_no_image_uv_map_or_material_change(scene, addon):
    from hao_ext.operators.bake_operator import ModalBakeRunner
    from hao_addon.blender.bake_job import BakeJob

    obj = monkey()
    obj.data.uv_layers.remove(obj.data.uv_layers[0])
    mat = bpy.data.materials.new("Keep")
    if mat.node_tree is None:
        mat.use_nodes = True
    obj.data.materials.append(mat)
    nodes_before = sorted(n.name for n in mat.node_tree.nodes)
    images_before = set(bpy.data.images.keys())
    settings = small_settings(scene, uv_mode='AUTO', wire_material=True, directions=64)
    job = BakeJob(settings.to_request([obj]), bpy.context.evaluated_depsgraph_get)

    class FakeWM:
        calls = []

        def progress_begin(self, a, b): self.calls.append("begin")
        def progress_update(self, v): self.calls.append(v)
        def progress_end(self): self.calls.append("end")

    class FakeWorkspace:
        texts = []

        def status_text_set(self, t): self.texts.append(t)

    wm, ws = FakeWM(), FakeWorkspace()
    runner = ModalBakeRunner(job, wm, ws)
    while runner.fraction == 0.0:  # the xatlas unwrap first (a child process), then directions
        assert runner.tick(budget_s=0.05) is False
    assert 0 < runner.fraction < 1 and "Esc to cancel" in ws.texts[-1]
    assert "AO_UV" in obj.data.uv_layers  # the only early change...
    runner.cancel()
    assert "AO_UV" not in obj.data.uv_layers  # ...is rolled back
    assert set(bpy.data.images.keys()) == images_before
    assert sorted(n.name for n in mat.node_tree.nodes) == nodes_before
    assert wm.calls[-1] == "end" and ws.texts[-1] is None
    assert live_pass_count() == 0


def test_modal_runner_completes_and_commits(scene):
    from hao_ext.operators.bake_operator import ModalBakeRunner
    from hao_addon.blender.bake_job import BakeJob

    from hao_addon.bake import clear_cache
    obj = monkey()
    settings = small_settings(scene)
    assert bpy.ops.object.hao_bake_ao() == {'FINISHED'}  # the blocking bake, for comparison
    image = bpy.data.images[f"{obj.name}_AO"]
    blocking = np.array(image.pixels[:], np.float32)
    bpy.data.images.remove(image)
    clear_cache()  # the modal bake bakes again, not from the cache
    job = BakeJob(settings.to_request([obj]), bpy.context.evaluated_depsgraph_get)
    runner = ModalBakeRunner(job)
    fractions = []
    while not runner.tick(budget_s=0.01):
        fractions.append(runner.fraction)
    # It ran in steps (the UI stays live between them), its progress never went back...
    assert len(fractions) >= 2 and all(b >= a for a, b in zip(fractions, fractions[1:])), fractions
    # ...and it committed what the blocking bake makes: the same map, bit for bit.
    modal = np.array(bpy.data.images[f"{obj.name}_AO"].pixels[:], np.float32)
    assert modal.min() < 0.9  # the monkey occludes itself: a map, not a blank image
    np.testing.assert_array_equal(modal, blocking)


def test_undo_restores_the_scene(scene):
    obj = monkey()
    obj.data.uv_layers.remove(obj.data.uv_layers[0])
    small_settings(scene, uv_mode='AUTO', wire_material=True)
    bpy.ops.ed.undo_push(message="before bake")
    assert bpy.ops.object.hao_bake_ao() == {'FINISHED'}
    bpy.ops.ed.undo_push(message="after bake")
    bpy.ops.ed.undo()
    obj = bpy.data.objects["Suzanne"]
    assert "AO_UV" not in obj.data.uv_layers
    assert "Suzanne_AO" not in bpy.data.images
    assert obj.active_material is None


def test_twenty_bakes_leave_no_gpu_resources_or_state(scene):
    from hao_addon.gpu.shaders import cached_shader_count
    obj = monkey()
    small_settings(scene, directions=8, size=64)
    bpy.ops.object.hao_bake_ao()
    state, shaders = snapshot_state(), cached_shader_count()
    for i in range(20):
        scene.hao_bake.seed = i + 1  # defeat the cache: every bake really runs
        assert bpy.ops.object.hao_bake_ao() == {'FINISHED'}
    assert live_pass_count() == 0
    assert snapshot_state() == state
    assert cached_shader_count() == shaders  # variants compile once, never per bake
    assert len([i for i in bpy.data.images if i.name.startswith(obj.name)]) == 1


def test_selected_occluders_darken_the_floor(scene):
    from hao_addon.blender.images import image_pixels_gray
    floor = soup_to_object(scenes.grid_plane(8.0, 16), "Floor")
    ball = soup_to_object(scenes.uv_sphere(1.0, (0, 0, 1.0), 32, 16), "Ball")
    small_settings(scene, occluders='target')
    select_only(floor)
    bpy.ops.object.hao_bake_ao()
    alone = image_pixels_gray(bpy.data.images["Floor_AO"])
    bpy.data.images.remove(bpy.data.images["Floor_AO"])
    np.testing.assert_allclose(alone, 1.0, atol=1e-5)
    small_settings(scene, occluders='selected')
    select_only(floor, ball)
    bpy.ops.object.hao_bake_ao()  # bakes both selected meshes, each occluding the other
    shaded = image_pixels_gray(bpy.data.images["Floor_AO"])
    assert shaded[64, 64] < 0.2 and shaded[2, 2] > 0.95  # contact point dark, corners open
    assert "Ball_AO" in bpy.data.images


def unwrap_children() -> list[int]:
    import os
    from pathlib import Path
    pid = os.getpid()
    kids = [int(c) for c in Path(f"/proc/{pid}/task/{pid}/children").read_text().split()]
    return [k for k in kids if "unwrap_worker" in Path(f"/proc/{k}/cmdline").read_text(errors="replace")]


def test_esc_during_the_unwrap_stops_xatlas_and_changes_nothing(scene):
    from hao_ext.operators.bake_operator import ModalBakeRunner
    from hao_addon.blender.bake_job import BakeJob
    import time

    bpy.ops.mesh.primitive_uv_sphere_add(segments=400, ring_count=200)  # 160,000 triangles: a second of unwrap
    obj = bpy.context.active_object
    obj.data.uv_layers.remove(obj.data.uv_layers[0])
    images_before = set(bpy.data.images.keys())
    job = BakeJob(small_settings(scene, uv_mode='AUTO').to_request([obj]), bpy.context.evaluated_depsgraph_get)
    runner = ModalBakeRunner(job)
    assert runner.tick(budget_s=0.3) is False
    assert runner.fraction == 0.0 and runner.status.startswith("Unwrapping 'Sphere'")
    assert unwrap_children()  # the unwrap runs in a child process, so the UI keeps ticking
    t0 = time.monotonic()
    runner.cancel()
    assert time.monotonic() - t0 < 1.0 and unwrap_children() == []
    assert [l.name for l in obj.data.uv_layers] == [] and set(bpy.data.images.keys()) == images_before
    assert live_pass_count() == 0


def test_uv_layout_problems_are_reported_as_warnings(scene, capfd):
    obj = monkey()
    uv = uv_array(obj.data, "UVMap").reshape(-1, 2)
    obj.data.uv_layers["UVMap"].uv.foreach_set("vector", (uv * 0.5 + [0.7, 0.0]).ravel())  # past u = 1
    small_settings(scene)
    capfd.readouterr()
    assert bpy.ops.object.hao_bake_ao() == {'FINISHED'}
    out = capfd.readouterr().out
    assert "Warning: 'Suzanne':" in out and "outside the 0..1 UV tile" in out, out


@pytest.mark.parametrize("scale", [1e-5, 1e10])
def test_tiny_and_huge_meshes_without_uvs_bake(scene, scale):
    # xatlas unwraps a unit-size copy: 1e10 units used to hang in it, 1e-5 packed no atlas.
    bpy.ops.mesh.primitive_cube_add(size=2.0 * scale)
    obj = bpy.context.active_object
    obj.data.uv_layers.remove(obj.data.uv_layers[0])
    small_settings(scene, uv_mode='AUTO')
    assert bpy.ops.object.hao_bake_ao() == {'FINISHED'}
    assert [l.name for l in obj.data.uv_layers] == ["AO_UV"]
    px = np.empty(128 * 128 * 4, np.float32)
    bpy.data.images[f"{obj.name}_AO"].pixels.foreach_get(px)
    assert np.isfinite(px).all() and px.reshape(-1, 4)[:, 0].max() == 1.0  # a lone convex cube is open


def test_selected_to_active_bakes_the_high_poly_onto_the_active_mesh(scene, capfd):
    """The checkbox: the active mesh (a plane over a ball on a floor) receives, the other
    selected meshes are its sources and occlude, it does not; only its image is made, and a
    large miss count is reported as a warning. A cage object with other topology is refused."""
    from hao_addon.blender.images import image_pixels_gray
    low = soup_to_object(scenes.grid_plane(4.0, 4, z=1.2), "Low")
    floor = soup_to_object(scenes.grid_plane(200.0, 16), "Floor", uv=False)
    ball = soup_to_object(scenes.uv_sphere(0.5, (0, 0, 0.5), 32, 16), "Ball", uv=False)
    before = uv_array(low.data, "UVMap")
    small_settings(scene, selected_to_active=True, occluders='selected')
    select_only(low, floor, ball)
    assert bpy.ops.object.hao_bake_ao() == {'FINISHED'}
    ao = image_pixels_gray(bpy.data.images["Low_AO"])
    assert "Floor_AO" not in bpy.data.images and "Ball_AO" not in bpy.data.images
    assert ao[2, 2] > 0.95 and ao[64, 64] > 0.9  # far floor and the ball's top: open, not under the plane
    assert 0.3 < ao[64, 50] < 0.9  # the floor next to the ball
    np.testing.assert_array_equal(uv_array(low.data, "UVMap"), before)
    capfd.readouterr()
    small_settings(scene, selected_to_active=True, max_ray_distance=0.8)
    assert bpy.ops.object.hao_bake_ao() == {'FINISHED'}
    assert "found no high-poly surface" in capfd.readouterr().out
    scene.hao_bake.cage_object = ball
    select_only(low, floor)
    with pytest.raises(RuntimeError, match="cage 'Ball' has"):
        bpy.ops.object.hao_bake_ao()
    scene.hao_bake.cage_object = None
    select_only(low)
    with pytest.raises(RuntimeError, match="select the high-poly meshes besides 'Low'"):
        bpy.ops.object.hao_bake_ao()
