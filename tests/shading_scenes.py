# SPDX-License-Identifier: GPL-3.0-or-later
"""Blender scenes shaded the way artists shade them, built the same way by the Cycles truth
script (tests/scripts/make_cycles_truths.py) and by the tests that compare with it.

Each case: a mesh from tests/data (or samples/), a UV layout (its own, or xatlas's stored
with the truth), and a shading: smooth, smooth with sharp edges by angle, or custom normals.
"""
from __future__ import annotations

import math
from pathlib import Path

import bpy
import numpy as np

from hao_addon.core.objfile import read_obj

ROOT = Path(__file__).resolve().parent.parent
DATA = ROOT / "tests" / "data"
TRUTH_SIZE = 256
TRUTH_SPP = 1024

# name: (mesh file, shading). Cycles' Shadow Terminator Geometry Offset (a per-object
# setting, default 0.1) lifts rays that leave near the terminator off the flat facets to the
# smooth surface the normals describe; HAO models it (core/bake/terminator.py, setting
# terminator_offset). On the strongly bent custom normals of Spot it makes Cycles 0.037
# brighter on average, so that shading is baked both ways: spot_custom with the offset off,
# spot_custom_default with Blender's default.
CASES = {
    "spot_smooth": (DATA / "spot.obj", "smooth"),
    "rocker_smooth": (DATA / "rocker-arm.obj", "smooth"),
    "fandisk_sharp": (DATA / "fandisk.obj", "sharp"),
    "spot_custom": (DATA / "spot.obj", "custom"),
    "spot_custom_default": (DATA / "spot.obj", "custom"),
}
SHARP_ANGLE = math.radians(30.0)
DEFAULT_TERMINATOR_OFFSET = 0.1  # Blender's default of Object.shadow_terminator_geometry_offset
TERMINATOR_OFFSETS = {"spot_custom": 0.0}


def terminator_offset(name: str) -> float:
    """The case's Shadow Terminator Geometry Offset (Cycles' truth and our bake alike)."""
    return TERMINATOR_OFFSETS.get(name, DEFAULT_TERMINATOR_OFFSET)


def truth_path(name: str) -> Path:
    return DATA / f"cycles_{name}.npz"


def corner_uvs(name: str, size: int = TRUTH_SIZE) -> np.ndarray:
    """(F, 3, 2) the case's UV layout: the file's own, else xatlas's (made once by the truth
    script and read back from the truth file, so tests bake exactly what Cycles baked)."""
    path, _ = CASES[name]
    v, t, uv, tu = read_obj(path)
    if uv is not None:
        return uv[tu]
    if truth_path(name).exists():
        return np.load(truth_path(name))["uvs"].astype(np.float64)
    from hao_addon.core.bake.unwrap import unwrap_in_process
    return unwrap_in_process(v, t, size)


def custom_vertex_normals(vertices: np.ndarray, triangles: np.ndarray) -> np.ndarray:
    """(V, 3) custom normals as a stylized-shading artist sets them: the smooth normal bent
    halfway towards the direction from the mesh's centre (rounder, softer shading)."""
    from hao_addon.core.geometry import smooth_vertex_normals
    corner = smooth_vertex_normals(vertices[triangles])
    smooth = np.zeros_like(vertices)
    smooth[triangles.ravel()] = corner.reshape(-1, 3)
    radial = vertices - vertices.mean(axis=0)
    radial /= np.maximum(np.linalg.norm(radial, axis=1, keepdims=True), 1e-12)
    bent = smooth + radial
    return bent / np.maximum(np.linalg.norm(bent, axis=1, keepdims=True), 1e-12)


def build_object(name: str, uvs: np.ndarray) -> bpy.types.Object:
    """The case's object in the current scene, named after the case, with UV map 'UVMap'."""
    path, shading = CASES[name]
    v, t, _uv, _tu = read_obj(path)
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata(v.tolist(), [], t.tolist())
    layer = mesh.uv_layers.new(name="UVMap")
    layer.uv.foreach_set("vector", uvs.reshape(-1).astype(np.float32))  # loops follow the triangles
    mesh.shade_smooth()
    if shading == "sharp":
        mesh.set_sharp_from_angle(angle=SHARP_ANGLE)
    elif shading == "custom":
        mesh.normals_split_custom_set_from_vertices(custom_vertex_normals(v, t).tolist())
    mesh.update()
    obj = bpy.data.objects.new(name, mesh)
    if hasattr(obj, "shadow_terminator_geometry_offset"):
        # Cycles reads it (the truths were made on 5.2; bpy 4.2 names no such property).
        obj.shadow_terminator_geometry_offset = terminator_offset(name)
    bpy.context.scene.collection.objects.link(obj)
    return obj


# Selected to Active: name -> (high-poly file, Decimate ratio of the low-poly, cage
# extrusion, max ray distance). The low-poly (decimated in Blender, unwrapped by xatlas) is
# stored with the truth, so the tests bake exactly the pair Cycles baked. Both are shaded
# smooth. At extrusion 0.005 (2 % of the bunny's 0.25 diagonal) 2 of 28.6k texel rays miss;
# the max ray distance (0.02) drops the 1 % that reach through to a far side.
HIGH_TO_LOW = {
    "bunny_high_to_low": (ROOT / "bench" / "data" / "stanford-bunny.obj", 0.02, 0.005, 0.02),
}


def _smooth_object(name: str, vertices: np.ndarray, triangles: np.ndarray, uvs: np.ndarray | None = None):
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata(vertices.tolist(), [], triangles.tolist())
    if uvs is not None:
        layer = mesh.uv_layers.new(name="UVMap")
        layer.uv.foreach_set("vector", uvs.reshape(-1).astype(np.float32))
    mesh.shade_smooth()
    mesh.update()
    obj = bpy.data.objects.new(name, mesh)
    bpy.context.scene.collection.objects.link(obj)
    return obj


def decimated_low_poly(name: str) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(vertices (V, 3), triangles (F, 3), corner UVs (F, 3, 2)) of the case's low-poly: the
    high-poly through Blender's Decimate (collapse) at the case's ratio, unwrapped by xatlas."""
    from hao_addon.core.bake.unwrap import unwrap_in_process
    path, ratio, _e, _d = HIGH_TO_LOW[name]
    v, t, _uv, _tu = read_obj(path)
    obj = _smooth_object("decimate", v, t)
    modifier = obj.modifiers.new("decimate", 'DECIMATE')
    modifier.ratio = ratio
    mesh = obj.evaluated_get(bpy.context.evaluated_depsgraph_get()).to_mesh()
    mesh.calc_loop_triangles()
    lv = np.array([x.co[:] for x in mesh.vertices], np.float64)
    lt = np.array([tri.vertices[:] for tri in mesh.loop_triangles], np.int64)
    bpy.data.objects.remove(obj)
    return lv, lt, unwrap_in_process(lv, lt, TRUTH_SIZE)


def build_high_to_low(name: str, low: tuple[np.ndarray, np.ndarray, np.ndarray]):
    """(low-poly object with UV map 'UVMap', high-poly object) of the case, both smooth."""
    path = HIGH_TO_LOW[name][0]
    v, t, _uv, _tu = read_obj(path)
    high = _smooth_object(name + "_high", v, t)
    low_obj = _smooth_object(name + "_low", *low)
    return low_obj, high


def evaluated_case(name: str):
    """(the case's evaluated soup with its shading normals, the mean of Cycles' two bakes
    (256, 256), that mean's noise variance per texel (256, 256), the interior texels (256, 256))
    in a fresh scene: what a calibration against Cycles needs."""
    from hao_addon.blender import mesh_data
    from hao_addon.core.bake.uv_raster import interior_mask, texel_surface_samples
    bpy.ops.wm.read_factory_settings(use_empty=True)
    truth = np.load(truth_path(name))
    uvs = truth["uvs"].astype(np.float64)
    obj = build_object(name, uvs)
    soup = mesh_data.evaluated_soup(obj, bpy.context.evaluated_depsgraph_get(), "UVMap", shading_normals=True)
    face, _bary, hits = texel_surface_samples(uvs, TRUTH_SIZE)
    a, b = truth["ao"].astype(np.float64), truth["ao_seed1"].astype(np.float64)
    return soup, 0.5 * (a + b), (a - b) ** 2 / 4.0, interior_mask(face, hits)
