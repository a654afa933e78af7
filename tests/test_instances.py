# SPDX-License-Identifier: GPL-3.0-or-later
"""Every occluder the scene shows: mesh instances (collection instances, nested ones) occlude
as the meshes themselves do (blender/instances.py), and the report counts them."""
from __future__ import annotations

import numpy as np

import bpy
from conftest import select_only, small_settings, soup_to_object
from hao_addon.core import scenes


def _bake_floor(scene, floor_obj):
    from hao_addon.blender.bake_job import BakeJob
    select_only(floor_obj)
    settings = small_settings(scene, occluders='visible', directions=64, size=64, margin=0, method='gather')
    job = BakeJob(settings.to_request([floor_obj]), bpy.context.evaluated_depsgraph_get)
    job.run()
    return job, job.results[0][2]


def _hidden_collection(name: str, *objects) -> bpy.types.Collection:
    """A collection holding `objects`, linked to the scene but excluded from the view layer
    (as linked assets and kitbash sets sit: shown only through instances)."""
    collection = bpy.data.collections.new(name)
    for obj in objects:
        for users in obj.users_collection:
            users.objects.unlink(obj)
        collection.objects.link(obj)
    bpy.context.scene.collection.children.link(collection)
    bpy.context.view_layer.layer_collection.children[name].exclude = True
    return collection


def _instance(name: str, collection, location=(0.0, 0.0, 0.0), parent_collection=None) -> bpy.types.Object:
    empty = bpy.data.objects.new(name, None)
    empty.instance_type, empty.instance_collection, empty.location = 'COLLECTION', collection, location
    (parent_collection or bpy.context.scene.collection).objects.link(empty)
    return empty


def test_a_collection_instance_occludes_as_its_mesh_does(scene):
    """The issue: a floor under a cube read 0.958; under the same cube shown by an Empty that
    instances its collection, 1.000, exit 0, no warning. Nested instances (an instance of a
    collection that instances another, moved) occlude where they stand."""
    floor_obj = soup_to_object(scenes.grid_plane(4.0, 4, name="floor"), "floor")
    cube = soup_to_object(scenes.box((-0.5, -0.5, 0.0), (0.5, 0.5, 1.0), name="cube"), "cube", uv=False)
    _job, direct = _bake_floor(scene, floor_obj)
    assert direct.stats["instanced_occluders"] == 0

    crates = _hidden_collection("crates", cube)
    _instance("crate_here", crates)
    job, instanced = _bake_floor(scene, floor_obj)
    assert instanced.stats["instanced_occluders"] == 1
    assert job.summary()[0]["instanced_occluders"] == 1
    # The same geometry, the same directions: the same map up to float rounding of the transform.
    both = direct.covered & instanced.covered
    assert np.abs(direct.ao - instanced.ao)[both].max() < 1e-3
    assert float(instanced.ao[both].mean()) < 0.97

    # Nested: a set that instances the crates collection, itself instanced 1.2 units over.
    bpy.data.objects.remove(bpy.data.objects["crate_here"])
    kit = bpy.data.collections.new("kit")
    _instance("crate_in_kit", crates, parent_collection=kit)
    bpy.context.scene.collection.children.link(kit)
    bpy.context.view_layer.layer_collection.children["kit"].exclude = True
    _instance("kit_here", kit, location=(1.2, 0.0, 0.0))
    _job, nested = _bake_floor(scene, floor_obj)
    assert nested.stats["instanced_occluders"] == 1
    # The floor is 4 units wide over 64 texels: the darkest texel moved 1.2 units (about 19 texels) in x.
    row = direct.ao[32]
    assert abs(int(np.argmin(nested.ao[32])) - int(np.argmin(row)) - round(1.2 / 4.0 * 64)) <= 2


def test_occluders_are_what_renders_as_in_cycles(scene):
    """Cycles' bake takes what renders: a mesh hidden in the viewport (the eye) still occludes,
    one disabled in renders (itself or its collection) does not; before, the opposite."""
    floor_obj = soup_to_object(scenes.grid_plane(4.0, 4, name="floor"), "floor")
    cube = soup_to_object(scenes.box((-0.5, -0.5, 0.0), (0.5, 0.5, 1.0), name="cube"), "cube", uv=False)
    _job, shown = _bake_floor(scene, floor_obj)
    cube.hide_set(True)
    _job, eye_hidden = _bake_floor(scene, floor_obj)
    assert np.array_equal(shown.ao, eye_hidden.ao) and shown.ao.min() < 0.5
    cube.hide_set(False)
    cube.hide_render = True
    _job, not_rendered = _bake_floor(scene, floor_obj)
    assert not_rendered.ao[not_rendered.covered].min() > 0.999
    cube.hide_render = False
    props = _hidden_collection("props", cube)
    bpy.context.view_layer.layer_collection.children["props"].exclude = False
    props.hide_render = True
    _job, collection_off = _bake_floor(scene, floor_obj)
    assert collection_off.ao[collection_off.covered].min() > 0.999
    crate = _instance("crate_here", props)  # an instance of what does not render does not either
    props.hide_render, cube.hide_render = False, True
    bpy.context.view_layer.layer_collection.children["props"].exclude = True
    _job, instanced_off = _bake_floor(scene, floor_obj)
    assert instanced_off.stats["instanced_occluders"] == 0 and crate.name == "crate_here"
