# SPDX-License-Identifier: GPL-3.0-or-later
"""Per-scene viewport AO settings (Scene.hao_view), saved with the .blend file."""

import bpy
from bpy.props import BoolProperty, EnumProperty, PointerProperty

from ..hao_addon.core.hao.view_settings import ViewAOSettings
from .setting_props import EnumAliases, enum_aliases, setting_annotations, settings_from


def _redraw(self, context):
    for window in getattr(context.window_manager, "windows", []):
        for area in window.screen.areas:
            if area.type == 'VIEW_3D':
                area.tag_redraw()


class HAO_PG_view_settings(EnumAliases, bpy.types.PropertyGroup):
    enabled: BoolProperty(
        name="HAO", description="Show Hybrid Ambient Occlusion in the 3D viewport: voxel-traced, so objects "
                                "off screen or hidden behind others still darken what they should",
        default=False, update=_redraw)
    region_mode: EnumProperty(
        name="Region", description="Region of interest that is voxelized; pixels outside it get no HAO",
        items=(('VISIBLE', "Visible Meshes", "The bounds of all visible mesh objects"),
               ('COLLECTION', "Collection", "The bounds of a collection's objects"),
               ('BOX', "Box Object", "The bounds of an object, for example an empty cube")),
        default='VISIBLE', update=_redraw)
    region_collection: PointerProperty(type=bpy.types.Collection, name="Collection",
                                       description="Collection whose bounds are the region", update=_redraw)
    region_object: PointerProperty(type=bpy.types.Object, name="Box", description="Object whose bounds are the region",
                                   update=_redraw)
    show_spheres: BoolProperty(name="Show Spheres", description="Draw the sphere proxies in the viewport",
                               default=False, update=_redraw)
    skip_baked: BoolProperty(
        name="Skip Baked Objects", description="Objects with a baked AO map (from Bake AO) still occlude but get "
                                               "no HAO of their own (the paper's static regions)",
        default=False, update=_redraw)

    unlimited: BoolProperty(
        name="Unlimited", description="Every occluder counts, however far (what Cycles' AO and the bake compute); "
                                      "the same as Distance 0, without losing the distance set",
        default=False, update=_redraw)

    def to_settings(self) -> ViewAOSettings:
        settings = settings_from(self, ViewAOSettings)
        return settings.with_(max_distance=0.0) if self.unlimited else settings


# Rays, steps, distance, grid, ... from the core's ViewAOSettings (one definition each).
HAO_PG_view_settings.__annotations__.update(setting_annotations(ViewAOSettings, update=_redraw))
HAO_PG_view_settings._enum_aliases = enum_aliases(ViewAOSettings)


def register() -> None:
    bpy.utils.register_class(HAO_PG_view_settings)
    bpy.types.Scene.hao_view = PointerProperty(type=HAO_PG_view_settings, name="HAO Viewport")


def unregister() -> None:
    del bpy.types.Scene.hao_view
    bpy.utils.unregister_class(HAO_PG_view_settings)
