# SPDX-License-Identifier: GPL-3.0-or-later
"""Per-scene bake settings (Scene.hao_bake), saved with the .blend file."""

import bpy
from bpy.props import BoolProperty, EnumProperty, FloatProperty, IntProperty, PointerProperty, StringProperty

from ..hao_addon.core.settings import BakeSettings
from ..hao_addon.blender.bake_job import BakeRequest


class HAO_PG_bake_settings(bpy.types.PropertyGroup):
    size: IntProperty(
        name="Size", description="Width and height of the AO map in texels",
        default=1024, min=16, max=16384, soft_max=8192, subtype='PIXEL')
    directions: IntProperty(
        name="Directions",
        description="Light directions the mesh is rendered from; noise falls roughly as 1/sqrt(directions) "
                    "and time grows linearly",
        default=256, min=1, max=65536, soft_max=4096)
    max_distance: FloatProperty(
        name="Max Distance",
        description="Occluders farther than this do not darken (0 = unlimited, like Cycles with a huge AO distance)",
        default=0.0, min=0.0, soft_max=100.0, subtype='DISTANCE', unit='LENGTH')
    falloff: EnumProperty(
        name="Falloff", description="How occlusion fades with distance (only with a Max Distance)",
        items=(('none', "None", "Full occlusion up to Max Distance, none beyond"),
               ('wendland', "Smooth (Wendland)", "Fades smoothly to zero at Max Distance (Hybrid AO paper, eq. 3)")),
        default='none')
    weighting: EnumProperty(
        name="Weighting", description="How directions over the hemisphere count",
        items=(('cosine', "Cosine", "Lambertian ambient occlusion (what Cycles bakes)"),
               ('uniform', "Uniform", "Fraction of the open hemisphere")),
        default='cosine')
    ignore_back_faces: BoolProperty(
        name="Ignore Back Faces", description="Faces seen from behind do not occlude (for open or single-sided meshes)",
        default=False)
    occluders: EnumProperty(
        name="Occluders", description="What casts occlusion onto the baked mesh",
        items=(('TARGET', "Self", "Only the baked mesh itself"),
               ('SELECTED', "Selected", "The baked mesh and the other selected meshes"),
               ('VISIBLE', "Visible", "Every visible mesh in the view layer")),
        default='SELECTED')
    margin: IntProperty(
        name="Margin", description="Texels the map is extended past every UV island, so filtering never reads the background",
        default=16, min=0, max=1024, subtype='PIXEL')
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
                                    "{object} is replaced by the object's name", default="", subtype='FILE_PATH')
    wire_material: BoolProperty(
        name="Add to Material", description="Add the AO image to the object's material and multiply it into Base Color",
        default=False)
    method: EnumProperty(
        name="Method", description="GPU bake algorithm",
        items=(('auto', "Auto", "Shadow-Map Gather for unlimited distance (fastest at equal error in our "
                                "benchmark), Histogram Scatter with a Max Distance"),
               ('scatter', "Histogram Scatter", "McGraw & Sowers: texel-area average, supports Max Distance"),
               ('gather', "Shadow-Map Gather", "Shadow maps sampled at texel centres (the paper's baseline); unlimited distance only")),
        default='auto')
    view_samples: FloatProperty(
        name="View Samples", description="Light-view pixels per texel: more is smoother and slower",
        default=2.0, min=0.25, max=64.0, soft_max=8.0)
    seed: IntProperty(name="Seed", description="Rotation of the direction set", default=0, min=0)

    def to_settings(self) -> BakeSettings:
        return BakeSettings(size=self.size, directions=self.directions, max_distance=self.max_distance,
                            falloff=self.falloff, weighting=self.weighting, ignore_back_faces=self.ignore_back_faces,
                            margin=self.margin, method=self.method, view_samples=self.view_samples, seed=self.seed)

    def to_request(self, targets: list) -> BakeRequest:
        uv = {'AUTO': "AUTO", 'ACTIVE': "", 'NAMED': self.uv_map}[self.uv_mode]
        return BakeRequest(targets=targets, settings=self.to_settings(), occluders=self.occluders, uv_map=uv,
                           image=self.image, filepath=self.filepath, wire_material=self.wire_material)


def register() -> None:
    bpy.utils.register_class(HAO_PG_bake_settings)
    bpy.types.Scene.hao_bake = PointerProperty(type=HAO_PG_bake_settings, name="HAO Bake")


def unregister() -> None:
    del bpy.types.Scene.hao_bake
    bpy.utils.unregister_class(HAO_PG_bake_settings)
