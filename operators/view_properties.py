# SPDX-License-Identifier: GPL-3.0-or-later
"""Per-scene viewport AO settings (Scene.hao_view), saved with the .blend file."""

import bpy
from bpy.props import BoolProperty, EnumProperty, FloatProperty, IntProperty, PointerProperty

from ..hao_addon.core.view_settings import GRID_MAX, GRID_MIN, ViewAOSettings


def _redraw(self, context):
    for window in getattr(context.window_manager, "windows", []):
        for area in window.screen.areas:
            if area.type == 'VIEW_3D':
                area.tag_redraw()


class HAO_PG_view_settings(bpy.types.PropertyGroup):
    enabled: BoolProperty(
        name="HAO", description="Show Hybrid Ambient Occlusion in the 3D viewport: voxel-traced, so objects "
                                "off screen or hidden behind others still darken what they should",
        default=False, update=_redraw)
    rays: IntProperty(name="Rays", description="Rays per AO-map pixel; the main cost (paper default 32)",
                      default=32, min=1, max=1024, soft_max=128, update=_redraw)
    steps: IntProperty(name="Steps", description="Fixed occupancy tests along each ray (paper default 8)",
                       default=8, min=1, max=256, soft_max=32, update=_redraw)
    spread: FloatProperty(name="Spread", description="Cone of the rays: 1 = the whole hemisphere (the AO "
                                                     "definition); smaller gives sharper, more contrasted AO",
                          default=1.0, min=0.05, max=1.0, update=_redraw)
    max_distance: FloatProperty(name="Distance", description="d_max: occluders farther than this do not darken; "
                                                             "closer ones fade in smoothly (Wendland kernel)",
                                default=1.0, min=1e-4, soft_max=100.0, subtype='DISTANCE', unit='LENGTH',
                                update=_redraw)
    grid: IntProperty(name="Grid", description="Voxels along the longest side of the region of interest",
                      default=256, min=GRID_MIN, max=GRID_MAX, update=_redraw)
    scale: IntProperty(name="AO Scale", description="AO is sampled at 1/scale of the viewport resolution per "
                                                    "axis, then upsampled by the bilateral filter",
                       default=2, min=1, max=8, update=_redraw)
    filter_size: IntProperty(name="Filter", description="Bilateral filter window in pixels (0 = off)",
                             default=16, min=0, max=64, update=_redraw)
    strength: FloatProperty(name="Strength", description="How much the viewport is darkened (1 = the computed AO)",
                            default=1.0, min=0.0, max=1.0, subtype='FACTOR', update=_redraw)
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
    method: EnumProperty(
        name="Method", description="What casts the AO (see the README's benchmark for time against error)",
        items=(('hao', "HAO Voxels", "Voxel ray-marching against everything (static and deforming)"),
               ('far', "Sphere Proxies", "Only the sphere proxies of characters (fast, coarse)"),
               ('hao+far', "Voxels + Spheres", "Spheres for meshes that have proxies, voxels for the rest"),
               ('near', "Near Field", "Image-space AO from the two depth layers within Distance (Rays = samples); "
                                      "misses what is off screen"),
               ('near+far', "Near Field + Spheres", "Near field plus the sphere proxies (the paper's combination)")),
        default='hao', update=_redraw)
    epsilon: FloatProperty(name="Sphere Cut-off", description="Occlusion below which a sphere proxy stops "
                                                              "influencing (paper's epsilon): smaller reaches farther",
                           default=0.05, min=1e-4, max=0.99, update=_redraw)
    show_spheres: BoolProperty(name="Show Spheres", description="Draw the sphere proxies in the viewport",
                               default=False, update=_redraw)
    skip_baked: BoolProperty(
        name="Skip Baked Objects", description="Objects with a baked AO map (from Bake AO) still occlude but get "
                                               "no HAO of their own (the paper's static regions)",
        default=False, update=_redraw)

    def to_settings(self) -> ViewAOSettings:
        return ViewAOSettings(rays=self.rays, steps=self.steps, spread=self.spread, max_distance=self.max_distance,
                              grid=self.grid, scale=self.scale, filter_size=self.filter_size, strength=self.strength,
                              method=self.method, epsilon=self.epsilon)


def register() -> None:
    bpy.utils.register_class(HAO_PG_view_settings)
    bpy.types.Scene.hao_view = PointerProperty(type=HAO_PG_view_settings, name="HAO Viewport")


def unregister() -> None:
    del bpy.types.Scene.hao_view
    bpy.utils.unregister_class(HAO_PG_view_settings)
