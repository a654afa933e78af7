# SPDX-License-Identifier: GPL-3.0-or-later
"""Run in a fresh interpreter with BLENDER_USER_RESOURCES set to an empty folder: install the
built extension zip through Blender's extension system, enable it, bake AO with it."""
import sys

import bpy

zip_path, out_path = sys.argv[1], sys.argv[2]
bpy.ops.extensions.package_install_files(filepath=zip_path, repo="user_default", enable_on_install=True)
assert "bl_ext.user_default.hao_ao" in bpy.context.preferences.addons, list(bpy.context.preferences.addons.keys())
bpy.ops.mesh.primitive_monkey_add()
obj = bpy.context.active_object
obj.data.uv_layers.remove(obj.data.uv_layers[0])  # exercise the bundled xatlas wheel too
s = bpy.context.scene.hao_bake
s.size, s.directions, s.filepath = 128, 32, out_path
assert bpy.ops.object.hao_bake_ao() == {'FINISHED'}
assert "AO_UV" in obj.data.uv_layers and f"{obj.name}_AO" in bpy.data.images
mod = sys.modules["bl_ext.user_default.hao_ao"]
assert mod.__file__.startswith(bpy.utils.user_resource('EXTENSIONS')), mod.__file__
print("INSTALLED_BAKE_OK")
