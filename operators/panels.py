# SPDX-License-Identifier: GPL-3.0-or-later
"""The AO tab of the 3D View sidebar."""
from __future__ import annotations

import bpy

from ..hao_addon.core.bake.settings import QUALITY_CAPS


class VIEW3D_PT_hao_bake(bpy.types.Panel):
    """Bake per-texel ambient occlusion on the GPU"""

    bl_label = "Bake AO"
    bl_idname = "VIEW3D_PT_hao_bake"
    bl_space_type = 'VIEW_3D'
    bl_region_type = 'UI'
    bl_category = "AO"

    def draw(self, context):
        layout = self.layout
        layout.use_property_split = True
        layout.use_property_decorate = False
        settings = context.scene.hao_bake
        col = layout.column()
        col.prop(settings, "size")
        col.prop(settings, "quality")
        if settings.quality in QUALITY_CAPS:  # a preset caps itself
            col.label(text=f"Up to {QUALITY_CAPS[settings.quality]} directions")
        else:
            col.prop(settings, "directions", **({} if settings.quality == "fixed" else {"text": "Max Directions"}))
        sub = col.column()
        sub.active = settings.quality in ("custom", "fixed")
        sub.prop(settings, "max_error")
        col.prop(settings, "method")
        col.separator()
        col.prop(settings, "max_distance")
        sub = col.column()
        sub.active = settings.max_distance > 0.0
        sub.prop(settings, "falloff")
        col.prop(settings, "weighting")
        col.prop(settings, "spread_angle")
        col.prop(settings, "min_distance")
        col.prop(settings, "normals")
        sub = col.column()
        sub.active = settings.normals == 'mesh'
        sub.prop(settings, "terminator")
        offset = sub.column()
        offset.active = settings.normals == 'mesh' and settings.terminator == 'setting'
        offset.prop(settings, "terminator_offset")
        col.prop(settings, "ignore_back_faces")
        col.prop(settings, "alpha")
        sub = col.column()
        sub.active = settings.alpha == "clip"
        sub.prop(settings, "alpha_clip")
        col.prop(settings, "occluders")
        col.prop(settings, "samples_per_texel")
        col.separator()
        col.prop(settings, "selected_to_active")
        sub = col.column()
        sub.active = settings.selected_to_active
        sub.prop(settings, "cage_object")
        extrusion = sub.column()
        extrusion.active = settings.selected_to_active and settings.cage_object is None
        extrusion.prop(settings, "cage_extrusion")
        sub.prop(settings, "max_ray_distance")
        col.prop(settings, "match_names")
        sub = col.column()
        sub.active = settings.match_names
        sub.prop(settings, "low_suffix")
        sub.prop(settings, "high_suffix")
        sub.prop(settings, "group_occluders")
        col.separator()
        col.prop(settings, "target")
        if settings.target == "color-attribute":
            col.prop(settings, "color_domain")
        outer, col = col, col.column()
        col.active = settings.target == "image"  # the image outputs
        col.prop(settings, "uv_mode")
        if settings.uv_mode == 'NAMED':
            obj = context.active_object
            if obj is not None and obj.type == 'MESH':
                col.prop_search(settings, "uv_map", obj.data, "uv_layers", text="Name")
            else:
                col.prop(settings, "uv_map", text="Name")
        col.prop(settings, "margin")
        col.prop(settings, "texture_set")
        col.template_ID(settings, "image", new="image.new", open="image.open")
        col.prop(settings, "filepath")
        sub = col.column()
        sub.prop(settings, "png_bits")
        dither = sub.column()
        dither.active = settings.png_bits == "8"
        dither.prop(settings, "dither")
        col.prop(settings, "frame_range")
        col.prop(settings, "wire_material")
        col.prop(settings, "bent_normals")
        sub = col.column()
        sub.active = settings.bent_normals
        sub.prop(settings, "bent_space")
        sub.prop(settings, "bent_convention")
        sub.prop(settings, "bent_filepath")
        col.prop(settings, "thickness")
        sub = col.column()
        sub.active = settings.thickness
        sub.prop(settings, "thickness_distance")
        sub.prop(settings, "thickness_filepath")
        col.prop(settings, "error_filepath")
        col.prop(settings, "verify")
        sub = col.column()
        sub.active = settings.verify > 0
        sub.prop(settings, "verify_max_error")
        outer.prop(settings, "view_samples")
        layout.separator()
        layout.operator("object.hao_bake_ao", icon='RENDER_STILL')


class VIEW3D_PT_hao_view(bpy.types.Panel):
    """Hybrid Ambient Occlusion in the viewport and from the camera"""

    bl_label = "Viewport AO (HAO)"
    bl_idname = "VIEW3D_PT_hao_view"
    bl_space_type = 'VIEW_3D'
    bl_region_type = 'UI'
    bl_category = "AO"

    def draw_header(self, context):
        self.layout.prop(context.scene.hao_view, "enabled", text="")

    def draw(self, context):
        layout = self.layout
        layout.use_property_split = True
        layout.use_property_decorate = False
        props = context.scene.hao_view
        col = layout.column()
        col.prop(props, "rays")
        col.prop(props, "march")
        col.prop(props, "steps")
        col.prop(props, "spread")
        col.prop(props, "unlimited")
        sub = col.column()
        sub.active = not props.unlimited
        sub.prop(props, "max_distance")
        sub.prop(props, "falloff")
        col.prop(props, "grid")
        sub = col.column()
        sub.active = props.march == "hierarchical"
        sub.prop(props, "cascades")
        col.prop(props, "scale")
        col.prop(props, "filter_size")
        col.prop(props, "strength")
        col.separator()
        col.prop(props, "region_mode")
        if props.region_mode == 'COLLECTION':
            col.prop(props, "region_collection")
        elif props.region_mode == 'BOX':
            col.prop(props, "region_object")
        col.prop(props, "skip_baked")
        col.separator()
        col.prop(props, "method")
        sub = col.column()
        sub.active = props.method == "near+far"
        sub.prop(props, "near_radius")
        col.prop(props, "epsilon")
        col.prop(props, "show_spheres")
        row = layout.row(align=True)
        row.operator("object.hao_sync_spheres", icon='MESH_UVSPHERE')
        row.operator("object.hao_clear_spheres", text="", icon='X')
        layout.separator()
        layout.operator("render.hao_render_ao", icon='RENDER_STILL')


classes = (VIEW3D_PT_hao_bake, VIEW3D_PT_hao_view)
register, unregister = bpy.utils.register_classes_factory(classes)
