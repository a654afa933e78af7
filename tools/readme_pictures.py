# SPDX-License-Identifier: GPL-3.0-or-later
"""The README's pictures of the colour-attribute and UDIM outputs, and the command-line
bakes' pictures set on a mid-grey background (tools/readme_images.sh runs it after them):

    docs/images/spot_color_attribute.png  Spot's per-vertex AO (hao_ao, 256 directions) as
                                          Workbench renders the colour attribute, flat lit,
                                          values as they are (view transform Raw)
    docs/images/udim_tiles.png            a ball, a floor and a second ball baked onto UDIM
                                          tiles 1001, 1002, 1011 (one pass), laid out as the
                                          tiles sit in UV space (1012 unused, dark)
    docs/images/spot_ao.png               the AO map, texels outside Spot's UV islands (and
                                          their margins) in BACKGROUND grey
    docs/images/spot_viewport_ao.png      the viewport AO render over BACKGROUND grey (it is
                                          transparent where no surface is)
A white map or a white cow on a transparent or white background is a faint smudge on a light
page; on a mid grey both read on light and dark pages.
"""
from __future__ import annotations

import math
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

import bpy  # noqa: E402
import mathutils  # noqa: E402
import numpy as np  # noqa: E402

from hao_addon.bake import bake  # noqa: E402
from hao_addon.blender import mesh_data  # noqa: E402
from hao_addon.blender.color_attributes import store_color_attribute  # noqa: E402
from hao_addon.core import scenes  # noqa: E402
from hao_addon.core.bake.settings import BakeSettings  # noqa: E402
from hao_addon.core.geometry import TriangleSoup  # noqa: E402
from hao_addon.core.imageio import write_ao_file  # noqa: E402
from hao_addon.core.objfile import obj_soup, read_obj  # noqa: E402
from hao_addon.gpu.context import ensure_gpu_context  # noqa: E402

IMAGES = ROOT / "docs" / "images"
BACKGROUND = 0.42  # a mid grey (sRGB 107): reads on a light page and on a dark one


def on_background(path: Path, inside: np.ndarray | None = None) -> None:
    """Rewrite the picture at path (8-bit RGB) over BACKGROUND: where its alpha is 0, or, for
    a grey map, outside inside ((H, W) bool, row 0 at the top)."""
    import matplotlib.image as mpimg

    pixels = mpimg.imread(path).astype(np.float32)
    if pixels.ndim == 2:
        pixels = np.repeat(pixels[..., None], 3, axis=2)
    if pixels.shape[2] == 4:
        alpha, pixels = pixels[..., 3:], pixels[..., :3]
    else:
        alpha = inside[..., None].astype(np.float32)
    picture = pixels * alpha + BACKGROUND * (1.0 - alpha)
    mpimg.imsave(path, np.clip(picture, 0.0, 1.0))


def map_islands(obj: Path, size: int, margin: int) -> np.ndarray:
    """(size, size) bool, row 0 at the top: the texels a bake of obj's own UVs fills (its
    islands and their margins); one direction is enough, only the layout counts."""
    filled = bake(obj_soup(obj), [], BakeSettings(size=size, directions=1, margin=margin)).filled
    return np.flipud(filled.astype(bool))


def color_attribute_picture(path: Path) -> None:
    bpy.ops.wm.read_factory_settings(use_empty=True)
    v, t, _uv, _tu = read_obj(ROOT / "samples" / "spot.obj")
    mesh = bpy.data.meshes.new("Spot")
    mesh.from_pydata(v.tolist(), [], t.tolist())
    mesh.shade_smooth()
    obj = bpy.data.objects.new("Spot", mesh)
    scene = bpy.context.scene
    scene.collection.objects.link(obj)
    obj.rotation_euler = (math.radians(90), 0.0, math.radians(-30))  # the OBJ is Y-up
    bpy.context.view_layer.update()
    corners = np.array([obj.matrix_world @ mathutils.Vector(c) for c in obj.bound_box])
    centre, radius = corners.mean(axis=0), float(np.linalg.norm(np.ptp(corners, axis=0))) / 2
    depsgraph = bpy.context.evaluated_depsgraph_get()
    target = mesh_data.color_attribute_target(obj, depsgraph, "point")
    result = bake(mesh_data.evaluated_soup(obj, depsgraph, None), [],
                  BakeSettings(directions=256, target="color-attribute"), vertex_target=target)
    attribute = store_color_attribute(mesh, result.ao, "point")
    mesh.color_attributes.render_color_index = mesh.color_attributes.find(attribute.name)  # what renders show
    aim = bpy.data.objects.new("Aim", None)
    aim.location = centre
    scene.collection.objects.link(aim)
    camera = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
    scene.collection.objects.link(camera)
    camera.location = centre + radius * np.array([2.0, -1.7, 0.8])
    camera.constraints.new('TRACK_TO').target = aim
    scene.camera = camera
    scene.world = bpy.data.worlds.new("Grey")
    scene.world.color = (0.25, 0.25, 0.25)
    scene.render.engine = 'BLENDER_WORKBENCH'
    shading = scene.display.shading
    shading.light, shading.color_type = 'FLAT', 'VERTEX'  # the active colour attribute, unlit
    scene.render.resolution_x = scene.render.resolution_y = 256
    scene.view_settings.view_transform = 'Raw'  # the attribute's values as they are (AO is data)
    scene.render.filepath = str(path)
    bpy.ops.render.render(write_still=True)


def udim_picture(path: Path, size: int = 128) -> None:
    parts = [scenes.uv_sphere(0.5, (0, 0, 0.5), 48, 24), scenes.grid_plane(4.0, 8),
             scenes.uv_sphere(0.4, (1.0, 0.2, 0.4), 32, 16)]
    offsets = [(0, 0), (1, 0), (0, 1)]  # tiles 1001, 1002, 1011
    uvs = np.concatenate([0.02 + 0.96 * p.uvs + o for p, o in zip(parts, offsets)])
    soup = TriangleSoup(np.concatenate([p.positions for p in parts]), uvs, "udim")
    result = bake(soup, [], BakeSettings(size=size, directions=256, margin=4))
    sheet = np.full((2 * size + 2, 2 * size + 2), 0.15, np.float32)  # row 0 = v = 0, as the maps
    for tile_map, (u, v) in zip(result.ao, offsets):
        sheet[v * (size + 2):v * (size + 2) + size, u * (size + 2):u * (size + 2) + size] = tile_map
    write_ao_file(path, sheet)


if __name__ == "__main__":
    ensure_gpu_context()
    IMAGES.mkdir(parents=True, exist_ok=True)
    color_attribute_picture(IMAGES / "spot_color_attribute.png")
    udim_picture(IMAGES / "udim_tiles.png")
    on_background(IMAGES / "spot_ao.png", map_islands(ROOT / "samples" / "spot.obj", 256, 4))
    if (IMAGES / "spot_viewport_ao.png").is_file():
        on_background(IMAGES / "spot_viewport_ao.png")
    print("wrote", IMAGES / "spot_color_attribute.png", IMAGES / "udim_tiles.png", "and the grey backgrounds")
