# SPDX-License-Identifier: GPL-3.0-or-later
"""Viewport HAO in Blender: skips, GPU hygiene, evaluated meshes, the Render HAO operator,
the render-ao command line and the overlay's registration."""
from __future__ import annotations

import dataclasses

import bpy
import numpy as np

from conftest import run_hao
from hao_addon.core.hao import camera_math as cm
from hao_addon.core import scenes
from hao_addon.core.hao.view_scene import CLOSED, OPEN, object_from_soup
from hao_addon.core.hao.view_settings import ViewAOSettings


def _view(eye, width=96, height=72):
    return cm.perspective(0.9, width / height, 0.05, 100.0) @ cm.look_at(eye, (0.0, 0.0, 0.3)), width, height


def _scene_objects():
    sphere = scenes.uv_sphere(0.5, (0.0, 0.0, 0.5), 32, 16, name="sphere")
    plane = scenes.grid_plane(6.0, 6, name="plane")
    return [object_from_soup(plane, "plane"), object_from_soup(sphere, "sphere")]


def test_each_pass_runs_only_when_its_inputs_change(renderer):
    objs = _scene_objects()
    settings = ViewAOSettings(rays=8, grid=64)
    vp, w, h = _view((2.0, -2.5, 2.0))
    runs = lambda: {k: renderer.stats[k] for k in ("upload", "voxelize", "gbuffer", "ao", "filter")}  # noqa: E731
    renderer.render(objs, vp, w, h, settings)
    assert runs() == dict(upload=1, voxelize=1, gbuffer=1, ao=1, filter=1)
    renderer.render(objs, vp, w, h, settings)  # nothing changed: nothing runs
    assert runs() == dict(upload=1, voxelize=1, gbuffer=1, ao=1, filter=1)
    vp2, _, _ = _view((2.2, -2.4, 2.0))  # camera moved: no re-voxelization
    renderer.render(objs, vp2, w, h, settings)
    assert runs() == dict(upload=1, voxelize=1, gbuffer=2, ao=2, filter=2)
    renderer.render(objs, vp2, w, h, settings.with_(filter_size=4))  # filter setting: filter only
    assert runs() == dict(upload=1, voxelize=1, gbuffer=2, ao=2, filter=3)
    renderer.render(objs, vp2, w, h, settings.with_(filter_size=4, rays=16))  # sampling setting
    assert runs() == dict(upload=1, voxelize=1, gbuffer=2, ao=3, filter=4)
    moved = objs[1]
    moved = dataclasses.replace(moved, key="moved", offset=moved.offset + 0.1)
    renderer.render([objs[0], moved], vp2, w, h, settings.with_(filter_size=4, rays=16))  # geometry changed
    assert runs() == dict(upload=2, voxelize=2, gbuffer=3, ao=4, filter=5)
    renderer.render([objs[0], moved], vp2, w, h, settings.with_(filter_size=4, rays=16, grid=96))  # grid only
    assert runs() == dict(upload=2, voxelize=3, gbuffer=3, ao=5, filter=6)
    # With a region around the sphere, an object changing outside it is not re-voxelized.
    region = (np.array([-0.7, -0.7, -0.2]), np.array([0.7, 0.7, 1.3]))
    far = object_from_soup(scenes.uv_sphere(0.3, (2.5, 0.0, 0.3), 16, 8, name="far"), "far-a")
    s2 = settings.with_(filter_size=4, rays=16, grid=96)
    renderer.render([objs[0], moved, far], vp2, w, h, s2, region)
    base = runs()
    far.key = "far-b"
    far.offset = far.offset + 0.05
    renderer.render([objs[0], moved, far], vp2, w, h, s2, region)
    assert runs()["upload"] == base["upload"] + 1 and runs()["gbuffer"] == base["gbuffer"] + 1
    assert runs()["voxelize"] == base["voxelize"]


def test_background_baked_and_out_of_region_pixels_are_not_sampled(renderer):
    objs = _scene_objects()
    settings = ViewAOSettings(rays=8, grid=64, scale=2)
    vp, w, h = _view((2.0, -2.5, 2.0))
    renderer.render(objs, vp, w, h, settings)
    pos, _, _ = renderer.gbuffer.read()
    # An AO-map pixel is sampled when any pixel of its 2x2 block is covered.
    block_valid = (pos[..., 3] >= 1.0).reshape(h // 2, 2, w // 2, 2).any(axis=(1, 3))
    all_sampled = renderer.sampled_pixels()
    assert all_sampled == int(block_valid.sum()) < block_valid.size  # background skipped
    ao = renderer.read_ao()
    assert (ao[pos[..., 3] == 0.0] == 1.0).all()
    low = renderer.sampling.read()
    # The sphere carries a baked map: it still occludes (the floor's AO is unchanged, and
    # dark near it) but is not sampled.
    baked = [objs[0], dataclasses.replace(objs[1], receiver=0.5)]
    renderer.render(baked, vp, w, h, settings)
    pos_b, _, _ = renderer.gbuffer.read()
    plane_blocks = (pos_b[..., 3] >= 1.0).reshape(h // 2, 2, w // 2, 2).any(axis=(1, 3))
    assert 0 < renderer.sampled_pixels() <= int(plane_blocks.sum()) < all_sampled + 1
    assert renderer.sampled_pixels() < all_sampled
    low_b = renderer.sampling.read()
    floor = (pos[..., 2] < 1e-4).reshape(h // 2, 2, w // 2, 2).all(axis=(1, 3)) & block_valid
    np.testing.assert_array_equal(low_b[floor], low[floor])
    assert low_b[floor].min() < 0.7
    # A region of interest around the sphere only: floor pixels outside it are skipped.
    renderer.render(objs, vp, w, h, settings, region=(np.array([-0.6, -0.6, -0.1]), np.array([0.6, 0.6, 1.1])))
    assert renderer.sampled_pixels() < all_sampled // 2


def test_fifty_frames_leave_no_gpu_state_or_resources(gpu_context):
    import gpu
    from hao_addon.gpu import shaders, util
    from hao_addon.gpu.hao_renderer import HaoRenderer

    objs = _scene_objects()
    settings = ViewAOSettings(rays=4, grid=64)
    offscreen = gpu.types.GPUOffScreen(64, 64)
    with offscreen.bind():
        before = util.snapshot_state()
        renderer = HaoRenderer()
        renderer.render(objs, *_view((2.0, -2.5, 2.0)), settings)
        variants = shaders.cached_shader_count()
        for frame in range(50):
            vp, w, h = _view((2.0 + 0.01 * frame, -2.5, 2.0))
            renderer.render(objs, vp, w, h, settings)
            assert util.snapshot_state() == before
        assert shaders.cached_shader_count() == variants
        renderer.free()
        assert util.live_pass_count() == 0
    offscreen.free()


def _make_blend(path, with_modifier=False):
    bpy.ops.wm.read_factory_settings(use_empty=True)
    bpy.ops.mesh.primitive_plane_add(size=6.0)
    bpy.ops.mesh.primitive_uv_sphere_add(radius=0.5, location=(0.0, 0.0, 0.5), segments=32, ring_count=16)
    sphere = bpy.context.active_object
    bpy.ops.object.shade_smooth()
    if with_modifier:
        sphere.modifiers.new("sub", 'SUBSURF').levels = 1
    bpy.ops.object.camera_add(location=(2.5, -3.0, 2.2), rotation=(1.08, 0.0, 0.69))
    bpy.context.scene.camera = bpy.context.active_object
    bpy.context.active_object.name = "Cam"
    if path is not None:
        bpy.ops.wm.save_as_mainfile(filepath=str(path))
    return sphere


def test_scene_objects_are_evaluated_and_cached(addon, gpu_context):
    from hao_addon.blender.view_scene import clear_cache, visible_scene_objects
    clear_cache()
    sphere = _make_blend(None, with_modifier=True)
    dg = bpy.context.evaluated_depsgraph_get()
    objs = {o.name: o for o in visible_scene_objects(dg, bpy.context.view_layer)}
    # Subdivision applied: 4x the base mesh's triangles; the closed sphere is a solid.
    sphere.data.calc_loop_triangles()
    assert len(objs[sphere.name].positions) > 3 * len(sphere.data.loop_triangles)
    assert objs[sphere.name].fill == CLOSED and objs["Plane"].fill == OPEN
    again = {o.name: o for o in visible_scene_objects(dg, bpy.context.view_layer)}
    assert again[sphere.name] is objs[sphere.name]  # unchanged: the cached arrays are reused
    sphere.location.z += 0.25
    dg = bpy.context.evaluated_depsgraph_get()
    moved = {o.name: o for o in visible_scene_objects(dg, bpy.context.view_layer)}
    assert moved[sphere.name].key != objs[sphere.name].key
    assert moved["Plane"] is objs["Plane"]
    assert np.isclose(moved[sphere.name].world_positions()[..., 2].min()
                      - objs[sphere.name].world_positions()[..., 2].min(), 0.25, atol=1e-5)


def _run_cli(*args):
    return run_hao(args)


def test_render_ao_command_line(tmp_path):
    blend = tmp_path / "scene.blend"
    _make_blend(blend)
    out_png, out_exr = tmp_path / "ao.png", tmp_path / "ao.exr"
    res = _run_cli("render-ao", blend, "--camera", "Cam", "--width", 160, "--height", 120, "--out", out_png,
                   "--rays", 16, "--grid", 96)
    assert res.returncode == 0, res.stderr
    res = _run_cli("render-ao", blend, "--width", 160, "--height", 120, "--out", out_exr, "--rays", 16, "--grid", 96)
    assert res.returncode == 0, res.stderr
    img = bpy.data.images.load(str(out_exr))
    px = np.empty(160 * 120 * 4, np.float32)
    img.pixels.foreach_get(px)
    px = px.reshape(120, 160, 4)
    assert img.size[0] == 160 and img.size[1] == 120
    geometry = px[..., 3] > 0.5
    assert 0.2 < geometry.mean() < 1.0  # the sky (top rows) is background
    assert (px[~geometry][..., :3] == 1.0).all() and px[geometry][..., 0].min() < 0.7
    assert not geometry[-1].any()  # row -1 is the top in Blender's order: sky
    png = bpy.data.images.load(str(out_png))
    png.colorspace_settings.name = 'Non-Color'  # AO is data
    assert tuple(png.size) == (160, 120) and png.is_float  # 16-bit PNGs load as float buffers
    px_png = np.empty(160 * 120 * 4, np.float32)
    png.pixels.foreach_get(px_png)
    px_png = px_png.reshape(120, 160, 4)
    assert np.abs(px_png[..., 3] - px[..., 3]).max() < 1e-6
    # Blender associates alpha on load, so compare where alpha is 1.
    assert np.abs(px_png[geometry] - px[geometry]).max() < 2.0 / 65535
    for args, message in [(("--camera", "Nope"), "no camera named 'Nope'"),
                          (("--grid", 1000), "grid must be between 64 and 512"),
                          (("--rays", 0), "rays must be between 1 and 1024")]:
        res = _run_cli("render-ao", blend, "--out", tmp_path / "x.png", *args)
        assert res.returncode == 2 and message in res.stderr and len(res.stderr.strip().splitlines()) == 1
        assert not (tmp_path / "x.png").exists()


def test_render_operator_and_overlay_registration(addon, gpu_context, tmp_path):
    from hao_ext.operators import viewport_overlay
    _make_blend(None)
    scene = bpy.context.scene
    scene.render.resolution_x, scene.render.resolution_y, scene.render.resolution_percentage = 120, 90, 100
    scene.hao_view.rays, scene.hao_view.grid = 8, 64
    # The panel's Unlimited toggle: distance 0 while on, the distance set kept for when it is off.
    scene.hao_view.max_distance = 0.75  # exact in float32
    scene.hao_view.unlimited = True
    assert scene.hao_view.to_settings().max_distance == 0.0 and scene.hao_view.max_distance == 0.75
    scene.hao_view.unlimited = False
    assert scene.hao_view.to_settings().max_distance == 0.75
    out = tmp_path / "op.exr"
    assert bpy.ops.render.hao_render_ao(filepath=str(out)) == {'FINISHED'}
    img = bpy.data.images["HAO Render"]
    assert tuple(img.size) == (120, 90) and out.exists()
    # The overlay is registered with its handlers and does nothing in background mode.
    assert viewport_overlay._mark_dirty in bpy.app.handlers.depsgraph_update_post
    assert viewport_overlay._draw_handle is not None
    scene.hao_view.enabled = True
    viewport_overlay.draw_overlay()
    assert not viewport_overlay._session.renderers
    scene.camera = None
    assert not bpy.ops.render.hao_render_ao.poll()


def test_composite_darkens_by_ao_and_respects_depth(renderer):
    """The overlay's composite: colour * (1 - (1 - AO) * strength) where the surface is the
    front-most thing drawn; unchanged where something nearer was drawn, and on background."""
    import gpu
    from hao_addon.gpu import util
    from hao_addon.gpu.hao_composite import draw_composite
    from hao_addon.gpu.hao_gbuffer import GBufferPass

    objs = _scene_objects()
    vp, w, h = _view((2.0, -2.5, 2.0))
    renderer.render(objs, vp, w, h, ViewAOSettings(rays=8, grid=64))
    ao = renderer.read_ao()
    _, _, depth = renderer.gbuffer.read()
    # "Blender's" depth buffer: the same meshes drawn again (so the surfaces are front-most),
    # or a depth buffer cleared to 0 (something nearer everywhere).
    viewport = GBufferPass()  # freed even when an assertion fails: later tests count live passes
    try:
        viewport.set_geometry(np.concatenate([o.world_positions() for o in objs]).astype(np.float32),
                              np.concatenate([o.normals for o in objs]),
                              np.ones(sum(len(o.positions) for o in objs), np.float32))
        viewport.render(vp, w, h)
        nearer_depth = gpu.types.GPUTexture((w, h), format='DEPTH_COMPONENT32F')
        colour = gpu.types.GPUTexture((w, h), format='RGBA32F')
        base = np.array([0.8, 0.6, 0.4])
        for strength, scene_depth in ((1.0, viewport.depth), (0.5, viewport.depth), (1.0, nearer_depth)):
            fb = gpu.types.GPUFrameBuffer(depth_slot=scene_depth, color_slots=colour)
            with fb.bind():
                if scene_depth is nearer_depth:
                    fb.clear(color=(*base, 1.0), depth=0.0)
                else:
                    fb.clear(color=(*base, 1.0))
                draw_composite(renderer.ao_texture, renderer.gbuffer.depth, strength)
            got = util.texture_to_numpy(colour)[..., :3]
            if scene_depth is nearer_depth:
                expected = np.broadcast_to(base, got.shape)
            else:
                expected = base * (1.0 - (1.0 - ao) * strength)[..., None]
            assert np.abs(got - expected).max() < 1e-5, strength
            assert np.abs(got[depth >= 1.0] - base).max() < 1e-6
        assert ao.min() < 0.8  # there was AO to composite
    finally:
        viewport.free()
