# SPDX-License-Identifier: GPL-3.0-or-later
"""The HAO viewport overlay: a POST_VIEW draw handler on every 3D viewport that runs the
HaoRenderer with the region's matrices and darkens the image by the AO, plus the header
toggle. Registration adds the handlers and touches no GPU; the handler does nothing in
background mode or while HAO is off. Unregistration removes everything it added and frees
the renderers."""
from __future__ import annotations

import bpy
import numpy as np

_draw_handle = None
_renderers: dict[int, object] = {}  # one HaoRenderer per 3D-view region (its skips are per view)
_scene_dirty = True
_last_error: str = ""


@bpy.app.handlers.persistent  # survive file loads
def _mark_dirty(*_args) -> None:
    global _scene_dirty
    _scene_dirty = True


_cached_objects: list = []  # SceneObjects of the last depsgraph look


def draw_overlay() -> None:
    """Draw handler body (also called by tests with a bound framebuffer)."""
    global _scene_dirty, _cached_objects, _last_error
    context = bpy.context
    scene = context.scene
    props = getattr(scene, "hao_view", None)
    if props is None or not props.enabled or bpy.app.background:
        return
    region, rv3d = context.region, context.region_data
    if region is None or rv3d is None:
        return
    from ..hao_addon.blender.sphere_proxies import scene_spheres
    from ..hao_addon.blender.view_scene import region_box, visible_scene_objects
    from ..hao_addon.gpu.hao_composite import draw_composite
    from ..hao_addon.gpu.hao_renderer import HaoRenderer

    try:
        if _scene_dirty or not _cached_objects:
            # Only after a reported depsgraph update or frame change: hash the evaluated
            # meshes; unchanged ones keep their arrays and GPU batches.
            _cached_objects = visible_scene_objects(context.evaluated_depsgraph_get(), context.view_layer,
                                                    skip_baked=props.skip_baked)
            _scene_dirty = False
        if not _cached_objects:
            return
        settings = props.to_settings()
        spheres, proxied = (scene_spheres(context.view_layer, context.evaluated_depsgraph_get())
                            if settings.method != "hao" else (None, set()))
        for obj in _cached_objects:
            obj.proxied = obj.name in proxied
        renderer = _renderers.get(region.as_pointer())
        if renderer is None:
            renderer = _renderers[region.as_pointer()] = HaoRenderer()
        view_proj = np.array(rv3d.perspective_matrix)
        renderer.render(_cached_objects, view_proj, region.width, region.height, settings,
                        region_box(props), spheres)
        draw_composite(renderer.ao_texture, renderer.gbuffer.depth, props.strength)
        _last_error = ""
    except Exception as exc:  # never break the viewport: report once, then keep drawing
        message = f"HAO viewport AO stopped: {exc}"
        if message != _last_error:
            print(message)
            _last_error = message


def draw_header_toggle(self, context) -> None:
    props = getattr(context.scene, "hao_view", None)
    if props is not None:
        self.layout.prop(props, "enabled", text="HAO", toggle=True, icon='SHADING_RENDERED')


def free_renderers() -> None:
    global _cached_objects
    for r in _renderers.values():
        r.free()
    _renderers.clear()
    _cached_objects = []


def register() -> None:
    global _draw_handle
    _draw_handle = bpy.types.SpaceView3D.draw_handler_add(draw_overlay, (), 'WINDOW', 'POST_VIEW')
    bpy.types.VIEW3D_HT_header.append(draw_header_toggle)
    bpy.app.handlers.depsgraph_update_post.append(_mark_dirty)
    bpy.app.handlers.frame_change_post.append(_mark_dirty)
    bpy.app.handlers.load_post.append(_mark_dirty)


def unregister() -> None:
    global _draw_handle
    for handlers in (bpy.app.handlers.depsgraph_update_post, bpy.app.handlers.frame_change_post,
                     bpy.app.handlers.load_post):
        while _mark_dirty in handlers:
            handlers.remove(_mark_dirty)
    bpy.types.VIEW3D_HT_header.remove(draw_header_toggle)
    if _draw_handle is not None:
        bpy.types.SpaceView3D.draw_handler_remove(_draw_handle, 'WINDOW')
        _draw_handle = None
    free_renderers()
