# SPDX-License-Identifier: GPL-3.0-or-later
"""Build the sample scene for the viewport-AO job: Spot (samples/spot.obj, y-up) standing on a
floor, with a camera, saved as a .blend.

    .venv/bin/python samples/make_scene.py out/spot_scene.blend
"""
import math
import sys
from pathlib import Path

import bpy


def main(out: str) -> None:
    here = Path(__file__).resolve().parent
    bpy.ops.wm.read_factory_settings(use_empty=True)
    bpy.ops.wm.obj_import(filepath=str(here / "spot.obj"), forward_axis='NEGATIVE_Z', up_axis='Y')
    spot = bpy.context.selected_objects[0]
    bpy.context.view_layer.update()
    lowest = min((spot.matrix_world @ v.co).z for v in spot.data.vertices)
    spot.location.z -= lowest
    bpy.ops.mesh.primitive_plane_add(size=6.0)
    bpy.ops.object.camera_add(location=(3.9, -4.3, 2.6), rotation=(math.radians(70), 0.0, math.radians(42)))
    bpy.context.scene.camera = bpy.context.active_object
    bpy.context.active_object.name = "Camera"
    bpy.context.view_layer.objects.active = spot  # what a bake of this file without --object bakes
    Path(out).resolve().parent.mkdir(parents=True, exist_ok=True)
    bpy.ops.wm.save_as_mainfile(filepath=str(Path(out).resolve()))


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "out/spot_scene.blend")
