# SPDX-License-Identifier: GPL-3.0-or-later
"""Per-scene bake settings (Scene.hao_bake), saved with the .blend file."""

import bpy
from bpy.props import BoolProperty, EnumProperty, PointerProperty, StringProperty

from ..hao_addon import compat
from ..hao_addon.blender.bake_job import BakeRequest
from ..hao_addon.core.settings import BakeSettings
from .setting_props import setting_annotations, settings_from


class HAO_PG_bake_settings(bpy.types.PropertyGroup):
    # What the bake computes comes from BakeSettings (setting_annotations, below); these say
    # which objects, UV map and outputs the Blender job uses.
    occluders: EnumProperty(
        name="Occluders", description="What casts occlusion onto the baked mesh",
        items=(('TARGET', "Self", "Only the baked mesh itself"),
               ('SELECTED', "Selected", "The baked mesh and the other selected meshes"),
               ('VISIBLE', "Visible", "Every visible mesh in the view layer")),
        default='SELECTED')
    uv_mode: EnumProperty(
        name="UV Map", description="Which UV map the AO is baked into",
        items=(('AUTO', "Auto", "AO_UV if present, else the first UV map, else a new AO_UV map unwrapped with xatlas"),
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
    wire_material: BoolProperty(
        name="Add to Material", description="Add the AO image to the object's material and multiply it into Base Color",
        default=False)

    def to_settings(self) -> BakeSettings:
        return settings_from(self, BakeSettings)

    def to_request(self, targets: list) -> BakeRequest:
        uv = {'AUTO': "AUTO", 'ACTIVE': "", 'NAMED': self.uv_map}[self.uv_mode]
        return BakeRequest(targets=targets, settings=self.to_settings(), occluders=self.occluders, uv_map=uv,
                           image=self.image, filepath=self.filepath, wire_material=self.wire_material)


HAO_PG_bake_settings.__annotations__.update(setting_annotations(BakeSettings))


def register() -> None:
    bpy.utils.register_class(HAO_PG_bake_settings)
    bpy.types.Scene.hao_bake = PointerProperty(type=HAO_PG_bake_settings, name="HAO Bake")


def unregister() -> None:
    del bpy.types.Scene.hao_bake
    bpy.utils.unregister_class(HAO_PG_bake_settings)
