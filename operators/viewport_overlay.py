# SPDX-License-Identifier: GPL-3.0-or-later
"""The HAO viewport overlay: a POST_VIEW draw handler on every 3D viewport that renders the
region's AO through the viewport session (hao_addon/blender/viewport_session.py) and
darkens the image by it, plus the header toggle. Registration adds the handlers and touches
no GPU; the handler does nothing in background mode or while HAO is off. Unregistration
removes everything it added and frees the session's renderers."""
from __future__ import annotations

import bpy

from ..hao_addon.blender.viewport_session import ViewportSession

_draw_handle = None
_session = ViewportSession()
_last_error: str = ""


@bpy.app.handlers.persistent  # survive file loads
def _mark_dirty(*_args) -> None:
    _session.mark_dirty()


def draw_overlay() -> None:
    """Draw handler body (also called by tests with a bound framebuffer)."""
    global _last_error
    context = bpy.context
    props = getattr(context.scene, "hao_view", None)
    if props is None or not props.enabled or bpy.app.background:
        return
    if context.region is None or context.region_data is None:
        return
    from ..hao_addon.blender.view_scene import region_box
    from ..hao_addon.gpu.hao_composite import draw_composite

    try:
        renderer = _session.render(context, props.to_settings(), region_box(props))
        if renderer is not None:
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
    _session.free()


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
