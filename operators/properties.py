# SPDX-License-Identifier: GPL-3.0-or-later
"""Per-scene bake settings (Scene.hao_bake), saved with the .blend file."""

from dataclasses import replace

import bpy
from bpy.props import BoolProperty, EnumProperty, PointerProperty, StringProperty

from ..hao_addon import compat
from ..hao_addon.blender.bake_groups import bake_groups
from ..hao_addon.blender.bake_request import BakeRequest
from ..hao_addon.core.bake.settings import BakeSettings
from ..hao_addon.core.bake.job_options import JobOptions
from ..hao_addon.core.bake.map_kinds import EXTRA_MAPS
from ..hao_addon.core.bake.target_kinds import target_kind
from .setting_props import EnumAliases, enum_aliases, setting_annotations, settings_from


class HAO_PG_bake_settings(EnumAliases, bpy.types.PropertyGroup):
    # What the bake computes comes from BakeSettings, which meshes occlude and how outputs are
    # laid out from JobOptions (setting_annotations, below); these say which objects, UV map
    # and outputs the Blender job uses.
    uv_mode: EnumProperty(
        name="UV Map", description="Which UV map the AO is baked into",
        items=(('AUTO', "Auto", "AO_UV if present, else the first UV map, else a new AO_UV map unwrapped automatically (planar charts packed by xatlas)"),
               ('ACTIVE', "Active Render", "The UV map marked active for rendering"),
               ('NAMED', "Named", "The UV map named below")),
        default='AUTO')
    uv_map: StringProperty(name="UV Map Name", description="UV map to bake into when UV Map is Named", default="UVMap")
    image: PointerProperty(
        name="Image", type=bpy.types.Image,
        description="Existing image to overwrite (one object only); empty creates '<object>_AO'")
    filepath: StringProperty(
        name="Save To", description="Also write the map to this .png (16-bit) or .exr (32-bit float) file; "
                                    "{object} is replaced by the object's name", default="", subtype='FILE_PATH',
        options=compat.path_property_options())
    selected_to_active: BoolProperty(
        name="Selected to Active",
        description="Bake the other selected meshes (high-poly) onto the active one's UVs, as Cycles does: "
                    "they occlude, the active mesh does not",
        default=False)
    cage_object: PointerProperty(
        name="Cage Object", type=bpy.types.Object, poll=lambda _self, obj: obj.type == 'MESH',
        description="Selected to Active: rays start on this copy of the active mesh (same topology, moved "
                    "vertices) instead of the cage extrusion")
    auto_rebake: BoolProperty(
        name="Auto Re-bake",
        description="After an edit of a mesh, re-bake what it changed of the maps baked in this session (Re-bake "
                    "Changed, a second after the last edit, in Object Mode); off by default",
        default=False)
    frame_range: BoolProperty(
        name="Frame Range",
        description="Bake every frame of the scene's frame range (Start, End, Step), one file per frame: "
                    "{frame} in Save To becomes the frame number; frames with unchanged meshes reuse their bake",
        default=False)
    wire_material: BoolProperty(
        name="Add to Material",
        description="Add the AO image to the object's material as Blender's glTF exporter reads it: into the glTF "
                    "Material Output's Occlusion socket (exports carry it; renders do not darken twice)",
        default=False)
    multiply_base_color: BoolProperty(
        name="Multiply into Base Color",
        description="Also multiply the AO into the Principled BSDF's Base Color (renders then darken by it on top "
                    "of their own AO); off takes out a multiply an earlier bake added",
        default=False)

    def to_settings(self) -> BakeSettings:
        return settings_from(self, BakeSettings)

    def to_options(self) -> JobOptions:
        return settings_from(self, JobOptions)

    def to_request(self, targets: list, active=None) -> BakeRequest:
        """targets: the selected meshes; with Match Names they form bake groups by name, each
        low-poly baked from its group's highs; with Selected to Active the active one is
        baked and the others (not the cage) are its high-poly sources."""
        uv = {'AUTO': "AUTO", 'ACTIVE': "", 'NAMED': self.uv_map}[self.uv_mode]
        high_poly, cage, groups, notes = None, None, None, []
        if self.match_names:  # the selected meshes' names (or collections) make the groups
            groups, notes = bake_groups(targets, settings_from(self, JobOptions))
            targets = [low for group in groups for low in group.lows]
        elif self.selected_to_active:
            cage = self.cage_object
            high_poly = [o for o in targets if o != active and o != cage]
            if not high_poly and cage in targets:  # the cage alone besides the low-poly: say so, as the CLI does
                high_poly = [cage]
            targets = [active] if active is not None else []
        settings = self.to_settings()
        to_image = target_kind(settings.target).writes_images  # a colour attribute ignores the image outputs
        options = settings_from(self, JobOptions)
        options = replace(options, texture_set=options.texture_set and to_image and not self.selected_to_active)
        return BakeRequest(targets=targets, settings=settings, options=options, uv_map=uv, groups=groups, notes=notes,
                           image=self.image if to_image else None, filepath=self.filepath if to_image else "",
                           wire_material=self.wire_material and to_image,
                           multiply_base_color=self.multiply_base_color,
                           high_poly=high_poly, cage=cage,
                           map_paths=self.map_paths(settings),
                           frames=self.scene_frames() if self.frame_range else None, remember=True)

    def map_paths(self, settings: BakeSettings) -> dict[str, str]:
        """The Save ... To files of the maps besides the AO (core/bake/map_kinds.py) that this
        bake writes: image bakes only, each with its setting on where it needs one."""
        if not target_kind(settings.target).writes_images:
            return {}
        return {kind.key: path for kind in EXTRA_MAPS if (path := getattr(self, kind.property_name))
                and (not kind.setting or getattr(settings, kind.setting))}

    def scene_frames(self) -> list[int]:
        """The frames of the scene this property group belongs to (its frame range and step)."""
        scene = self.id_data
        return list(range(scene.frame_start, scene.frame_end + 1, max(1, scene.frame_step)))


def map_file_annotations() -> dict:
    """A Save ... To file field per map besides the AO (core/bake/map_kinds.py)."""
    return {kind.property_name: StringProperty(
        name=kind.panel_label, default="", subtype='FILE_PATH', options=compat.path_property_options(),
        description=f"Also write {kind.help} to this .png (16-bit) or .exr (32-bit float) file; {{object}} is "
                    f"replaced by the object's name") for kind in EXTRA_MAPS}


HAO_PG_bake_settings.__annotations__.update(setting_annotations(BakeSettings))
HAO_PG_bake_settings.__annotations__.update(setting_annotations(JobOptions))
HAO_PG_bake_settings.__annotations__.update(map_file_annotations())
HAO_PG_bake_settings._enum_aliases = {**enum_aliases(BakeSettings), **enum_aliases(JobOptions)}


def register() -> None:
    bpy.utils.register_class(HAO_PG_bake_settings)
    bpy.types.Scene.hao_bake = PointerProperty(type=HAO_PG_bake_settings, name="HAO Bake")


def unregister() -> None:
    del bpy.types.Scene.hao_bake
    bpy.utils.unregister_class(HAO_PG_bake_settings)
