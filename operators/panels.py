# SPDX-License-Identifier: GPL-3.0-or-later
"""The AO tab of the 3D View sidebar. The bake panel is laid out as Cycles' own Bake panel:
the Bake button and what to bake on top, then sub-panels (Output, Selected to Active, Maps,
Quality, Advanced; the rarely needed ones collapsed). The Maps sub-panel is drawn from the
map rows (core/bake/map_kinds.py)."""
from __future__ import annotations

import bpy

from ..hao_addon.core.bake.map_kinds import EXTRA_MAPS
from ..hao_addon.core.bake.settings import QUALITY_CAPS
from ..hao_addon.core.bake.target_kinds import target_kind


def _split_layout(layout):
    layout.use_property_split = True
    layout.use_property_decorate = False
    return layout.column()


def _props(layout, settings, *names: str) -> None:
    for name in names:
        layout.prop(settings, name)


def _active_column(col, active: bool):
    sub = col.column()
    sub.active = active
    return sub


class _BakeSubPanel:
    """A sub-panel of Bake AO (its idname is its class name): draw_settings(col, settings,
    context) fills a property-split column."""

    bl_space_type = 'VIEW_3D'
    bl_region_type = 'UI'
    bl_category = "AO"
    bl_parent_id = "VIEW3D_PT_hao_bake"

    def draw(self, context):
        self.draw_settings(_split_layout(self.layout), context.scene.hao_bake, context)


class VIEW3D_PT_hao_bake(bpy.types.Panel):
    """Bake per-texel ambient occlusion on the GPU"""

    bl_label = "Bake AO"
    bl_idname = "VIEW3D_PT_hao_bake"
    bl_space_type = 'VIEW_3D'
    bl_region_type = 'UI'
    bl_category = "AO"

    def draw(self, context):
        settings = context.scene.hao_bake
        row = self.layout.row(align=True)
        row.operator("object.hao_bake_ao", icon='RENDER_STILL')
        row.operator("object.hao_bake_ao", text="Re-bake Changed", icon='FILE_REFRESH').changed_only = True
        self.layout.prop(settings, "auto_rebake")
        col = _split_layout(self.layout)
        col.prop(settings, "target")
        for name in target_kind(settings.to_settings().target).settings:  # the Target's own settings (its row's)
            col.prop(settings, name)
        _props(col, settings, "size", "occluders", "method")


class VIEW3D_PT_hao_bake_output(_BakeSubPanel, bpy.types.Panel):
    """Where the AO map goes: UV map, image, file, frames, material"""

    bl_label = "Output"

    def draw_settings(self, col, settings, context):
        col.active = target_kind(settings.to_settings().target).writes_images  # the image outputs
        col.prop(settings, "uv_mode")
        if settings.uv_mode == 'NAMED':
            obj = context.active_object
            if obj is not None and obj.type == 'MESH':
                col.prop_search(settings, "uv_map", obj.data, "uv_layers", text="Name")
            else:
                col.prop(settings, "uv_map", text="Name")
        _props(col, settings, "margin", "texture_set")
        col.template_ID(settings, "image", new="image.new", open="image.open")
        _props(col, settings, "filepath", "png_bits")
        _active_column(col, settings.to_options().png_bits == "8").prop(settings, "dither")
        _props(col, settings, "frame_range", "wire_material")
        _active_column(col, settings.wire_material).prop(settings, "multiply_base_color")


class VIEW3D_PT_hao_bake_selected(_BakeSubPanel, bpy.types.Panel):
    """Selected to Active, and bake groups matched by name"""

    bl_label = "Selected to Active"
    bl_options = {'DEFAULT_CLOSED'}

    def draw_header(self, context):
        self.layout.prop(context.scene.hao_bake, "selected_to_active", text="")

    def draw_settings(self, col, settings, context):
        sub = _active_column(col, settings.selected_to_active)
        sub.prop(settings, "cage_object")
        _active_column(sub, settings.selected_to_active and settings.cage_object is None).prop(settings,
                                                                                                "cage_extrusion")
        sub.prop(settings, "max_ray_distance")
        col.prop(settings, "match_names")
        sub = _active_column(col, settings.match_names)
        _props(sub, settings, "low_suffix", "high_suffix", "group_occluders")


class VIEW3D_PT_hao_bake_maps(_BakeSubPanel, bpy.types.Panel):
    """The maps baked beside the AO, one block per map row"""

    bl_label = "Maps"
    bl_options = {'DEFAULT_CLOSED'}

    def draw_settings(self, col, settings, context):
        col.active = target_kind(settings.to_settings().target).writes_images
        for kind in EXTRA_MAPS:
            block = col.column()
            if kind.setting:
                block.prop(settings, kind.setting)
                block = _active_column(block, getattr(settings, kind.setting))
            for name in kind.settings:
                block.prop(settings, name)
            block.prop(settings, kind.property_name)


class VIEW3D_PT_hao_bake_quality(_BakeSubPanel, bpy.types.Panel):
    """How exact the map must be, and checking it"""

    bl_label = "Quality"

    def draw_settings(self, col, settings, context):
        values = settings.to_settings()  # the core's words, not the enums' identifiers
        col.prop(settings, "quality")
        if values.quality in QUALITY_CAPS:  # a preset caps itself
            col.label(text=f"Up to {QUALITY_CAPS[values.quality]} directions")
        else:
            col.prop(settings, "directions", **({} if values.quality == "fixed" else {"text": "Max Directions"}))
        _active_column(col, values.quality in ("custom", "fixed")).prop(settings, "max_error")
        _props(col, settings, "view_samples", "samples_per_texel", "texel_sets", "seed")
        checked = _active_column(col, target_kind(values.target).writes_images)  # texels of a UV layout
        checked.prop(settings, "verify")
        _active_column(checked, settings.verify > 0).prop(settings, "verify_max_error")


class VIEW3D_PT_hao_bake_advanced(_BakeSubPanel, bpy.types.Panel):
    """What counts as an occluder and how rays leave the surface"""

    bl_label = "Advanced"
    bl_options = {'DEFAULT_CLOSED'}

    def draw_settings(self, col, settings, context):
        values = settings.to_settings()  # the core's words, not the enums' identifiers
        col.prop(settings, "max_distance")
        _active_column(col, values.max_distance > 0.0).prop(settings, "falloff")
        _props(col, settings, "weighting", "spread_angle", "min_distance", "normals")
        sub = _active_column(col, values.normals == 'mesh')
        sub.prop(settings, "terminator")
        _active_column(sub, values.normals == 'mesh' and values.terminator == 'setting').prop(
            settings, "terminator_offset")
        _props(col, settings, "ignore_back_faces", "alpha")
        _active_column(col, values.alpha == "clip").prop(settings, "alpha_clip")


BAKE_PANELS = (VIEW3D_PT_hao_bake, VIEW3D_PT_hao_bake_output, VIEW3D_PT_hao_bake_selected, VIEW3D_PT_hao_bake_maps,
               VIEW3D_PT_hao_bake_quality, VIEW3D_PT_hao_bake_advanced)


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
        values = props.to_settings()  # the core's words, not the enums' identifiers
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
        sub.active = values.march == "hierarchical"
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
        sub.active = values.method == "near+far"
        sub.prop(props, "near_radius")
        col.prop(props, "epsilon")
        col.prop(props, "show_spheres")
        row = layout.row(align=True)
        row.operator("object.hao_sync_spheres", icon='MESH_UVSPHERE')
        row.operator("object.hao_clear_spheres", text="", icon='X')
        layout.separator()
        layout.operator("render.hao_render_ao", icon='RENDER_STILL')


classes = (*BAKE_PANELS, VIEW3D_PT_hao_view)
register, unregister = bpy.utils.register_classes_factory(classes)
