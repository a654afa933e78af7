# SPDX-License-Identifier: GPL-3.0-or-later
"""Headless HAO render from a scene camera: the viewport overlay's passes (one HaoRenderer),
read back as an image. Used by the Render AO operator and ``python -m hao_addon render-ao``."""
from __future__ import annotations

import bpy
import numpy as np

from .blender.sphere_proxies import scene_spheres
from .blender.view_scene import camera_view_projection, visible_scene_objects
from .core.errors import ViewInputError
from .core.hao.methods import method_plan
from .core.hao.view_settings import RenderSize, ViewAOSettings, render_gpu_bytes


def render_camera_ao(scene: bpy.types.Scene, camera: bpy.types.Object, width: int, height: int,
                     settings: ViewAOSettings, region=None, skip_baked: bool = False,
                     renderer=None) -> np.ndarray:
    """(H, W, 4) float32 RGBA, row 0 at the bottom: accessibility in RGB (1 = open), alpha 1
    on geometry and 0 on background (whose RGB is 1). `renderer`: a HaoRenderer to reuse
    (its skips then apply across calls); by default a temporary one."""
    from .gpu.context import ensure_gpu_context
    from .gpu.hao_renderer import HaoRenderer
    from .gpu.util import check_render_limits, texture_to_numpy

    if camera is None or camera.type != 'CAMERA':
        raise ViewInputError("no camera: pass --camera NAME or give the scene a camera")
    settings = settings.validated()
    RenderSize(width, height).validated()
    ensure_gpu_context()
    check_render_limits(width, height, render_gpu_bytes(width, height, settings))
    depsgraph = bpy.context.evaluated_depsgraph_get()
    view_layer = bpy.context.view_layer
    objects = visible_scene_objects(depsgraph, view_layer, skip_baked=skip_baked)
    if not objects:
        raise ViewInputError(f"scene '{scene.name}' has no visible mesh objects")
    spheres = scene_spheres(view_layer, depsgraph)[0] if method_plan(settings.method).spheres else None
    view_proj = camera_view_projection(camera, depsgraph, width, height)
    own = renderer is None
    renderer = renderer or HaoRenderer()
    try:
        renderer.render(objects, view_proj, width, height, settings, region, spheres)
        ao = renderer.read_ao()
        coverage = texture_to_numpy(renderer.gbuffer.position)[..., 3] > 0.0
    finally:
        if own:
            renderer.free()
    if not coverage.any():  # an empty picture is no AO: said as plainly as no mesh at all
        raise ViewInputError(f"scene '{scene.name}' has no visible mesh objects in the view of '{camera.name}': "
                             f"every mesh lies outside its frame or its clip range ({camera.data.clip_start:g} "
                             f"to {camera.data.clip_end:g})")
    rgba = np.empty((height, width, 4), np.float32)
    rgba[..., :3] = ao[..., None]
    rgba[..., 3] = coverage
    return rgba
