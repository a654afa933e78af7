# SPDX-License-Identifier: GPL-3.0-or-later
"""What the viewport overlay keeps between redraws (Blender glue): one HaoRenderer per 3D-view
region, freed when its region closes; the scene objects of the last depsgraph look and the
object cache behind them; the sphere proxies. operators/viewport_overlay.py holds one
session and calls draw() from its draw handler."""
from __future__ import annotations

import numpy as np

from ..core.hao.methods import method_plan
from ..core.hao.view_scene import SceneObject
from ..core.hao.view_settings import ViewAOSettings
from .sphere_proxies import scene_spheres
from .view_scene import visible_scene_objects


def open_view_regions(window_manager) -> set[int]:
    """Pointers of the WINDOW regions of every open 3D view."""
    pointers = set()
    for window in getattr(window_manager, "windows", []):
        for area in window.screen.areas:
            if area.type == 'VIEW_3D':
                pointers.update(r.as_pointer() for r in area.regions if r.type == 'WINDOW')
    return pointers


class ViewportSession:
    def __init__(self) -> None:
        self.renderers: dict[int, object] = {}  # region pointer -> HaoRenderer (its skips are per view)
        self.object_cache: dict = {}  # view_scene's per-object cache: unchanged meshes keep their arrays
        self.objects: list[SceneObject] = []
        self.dirty = True  # a depsgraph update or frame change was reported since the last look

    def mark_dirty(self) -> None:
        self.dirty = True

    def scene_objects(self, context, skip_baked: bool) -> list[SceneObject]:
        """The visible meshes, looked at again only after a reported change."""
        if self.dirty or not self.objects:
            self.objects = visible_scene_objects(context.evaluated_depsgraph_get(), context.view_layer,
                                                 skip_baked=skip_baked, cache=self.object_cache)
            self.dirty = False
        return self.objects

    def renderer_for(self, region_pointer: int, open_regions: set[int] | None = None):
        """The region's renderer (made on first use); renderers of regions no longer in
        open_regions are freed first."""
        from ..gpu.hao_renderer import HaoRenderer
        if open_regions is not None:
            self.prune(open_regions | {region_pointer})
        renderer = self.renderers.get(region_pointer)
        if renderer is None:
            renderer = self.renderers[region_pointer] = HaoRenderer()
        return renderer

    def prune(self, open_regions: set[int]) -> int:
        """Free the renderers of closed regions; returns how many were freed."""
        closed = [p for p in self.renderers if p not in open_regions]
        for pointer in closed:
            self.renderers.pop(pointer).free()
        return len(closed)

    def render(self, context, settings: ViewAOSettings, region_box=None):
        """Render the region's AO (what changed since its last frame); returns its renderer."""
        objects = self.scene_objects(context, getattr(context.scene.hao_view, "skip_baked", False))
        if not objects:
            return None
        spheres = (scene_spheres(context.view_layer, context.evaluated_depsgraph_get())[0]
                   if method_plan(settings.method).spheres else None)
        region = context.region
        renderer = self.renderer_for(region.as_pointer(), open_view_regions(context.window_manager))
        renderer.render(objects, np.array(context.region_data.perspective_matrix), region.width, region.height,
                        settings, region_box, spheres)
        return renderer

    def free(self) -> None:
        for renderer in self.renderers.values():
            renderer.free()
        self.renderers.clear()
        self.objects = []
        self.object_cache.clear()
        self.dirty = True
