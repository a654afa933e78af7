# SPDX-License-Identifier: GPL-3.0-or-later
"""Render AO: the viewport HAO passes from the scene camera into an image datablock (and
optionally a file), at the scene's render resolution. Same code path as the overlay."""

import bpy
import numpy as np
from bpy.props import StringProperty

from ..hao_addon import compat

IMAGE_NAME = "HAO Render"


class RENDER_OT_hao_render_ao(bpy.types.Operator):
    """Render Hybrid Ambient Occlusion from the scene camera into the 'HAO Render' image"""

    bl_idname = "render.hao_render_ao"
    bl_label = "Render HAO"
    bl_options = {'REGISTER'}

    filepath: StringProperty(name="File", description="Also save to this .png (16-bit) or .exr (32-bit) file",
                             default="", subtype='FILE_PATH', options=compat.path_property_options())

    @classmethod
    def poll(cls, context):
        if context.scene is None or context.scene.camera is None:
            cls.poll_message_set("The scene has no camera")
            return False
        return True

    def execute(self, context):
        from ..hao_addon.blender.paths import absolute_path
        from ..hao_addon.blender.view_scene import region_box
        from ..hao_addon.core.errors import UserInputError
        from ..hao_addon.core.imageio import check_writable, write_ao_file
        from ..hao_addon.gpu.context import GPUUnavailableError
        from ..hao_addon.render_ao import render_camera_ao

        scene = context.scene
        props = scene.hao_view
        r = scene.render
        width = max(1, int(r.resolution_x * r.resolution_percentage / 100))
        height = max(1, int(r.resolution_y * r.resolution_percentage / 100))
        try:
            # The file is checked before rendering, so a bad path costs no GPU time.
            path = check_writable(absolute_path(self.filepath), width, height, 4) if self.filepath else None
            rgba = render_camera_ao(scene, scene.camera, width, height, props.to_settings(),
                                    region=region_box(props), skip_baked=props.skip_baked)
            if path is not None:
                write_ao_file(path, rgba)
        except (UserInputError, GPUUnavailableError, OSError) as exc:
            self.report({'ERROR'}, str(exc))
            return {'CANCELLED'}
        image = bpy.data.images.get(IMAGE_NAME)
        if image is not None and (image.size[0], image.size[1]) != (width, height):
            image.scale(width, height)
        if image is None:
            image = bpy.data.images.new(IMAGE_NAME, width, height, alpha=True, float_buffer=True)
            image.colorspace_settings.name = 'Non-Color'
        image.pixels.foreach_set(np.ascontiguousarray(rgba, np.float32).ravel())
        image.update()
        self.report({'INFO'}, f"HAO rendered {width}x{height} into '{image.name}'")
        return {'FINISHED'}


def register() -> None:
    bpy.utils.register_class(RENDER_OT_hao_render_ao)


def unregister() -> None:
    bpy.utils.unregister_class(RENDER_OT_hao_render_ao)
