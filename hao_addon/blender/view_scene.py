# SPDX-License-Identifier: GPL-3.0-or-later
"""SceneObjects (hao_addon/core/hao/view_scene.py) from the depsgraph: evaluated visible meshes
(modifiers and armatures applied) in world space, with smooth/flat corner normals as
Blender shades them.

Change detection: an object's key is a hash of its world matrix and evaluated vertex
positions (one foreach_get and one hash, a few ms per million vertices). Triangulation,
normals, the solidity test and the GPU upload are redone only when the key changes, so an
unchanged object costs the hash, and a frame where nothing changed costs nothing (the
overlay only looks when a depsgraph update or frame change was reported)."""
from __future__ import annotations

import hashlib

import bpy
import mathutils
import numpy as np

from ..core.hao.view_scene import OPEN, SceneObject, fill_class
from .mesh_arrays import read_positions

BAKED_AO_PROPERTY = "hao_ao_image"  # set on objects by the Bake AO operator

_DEFAULT_CACHE: dict[str, tuple[object, SceneObject]] = {}


def _key(obj_eval, mesh) -> str:
    co = read_positions(mesh)
    h = hashlib.blake2b(digest_size=16)
    h.update(np.asarray(obj_eval.matrix_world, np.float32).tobytes())
    h.update(co.tobytes())
    h.update(len(mesh.polygons).to_bytes(8, "little"))
    return h.hexdigest()


def _build(obj_eval, mesh, key: str) -> SceneObject:
    mesh.calc_loop_triangles()
    n_tri = len(mesh.loop_triangles)
    co = read_positions(mesh).astype(np.float64)
    tri_verts = np.empty(n_tri * 3, np.int64)
    mesh.loop_triangles.foreach_get("vertices", tri_verts)
    tri_loops = np.empty(n_tri * 3, np.int64)
    mesh.loop_triangles.foreach_get("loops", tri_loops)
    corner = np.empty(len(mesh.loops) * 3, np.float32)
    mesh.corner_normals.foreach_get("vector", corner)
    m = np.array(obj_eval.matrix_world, np.float64)
    world = co.reshape(-1, 3) @ m[:3, :3].T + m[:3, 3]
    normal_matrix = np.linalg.inv(m[:3, :3]).T if abs(np.linalg.det(m[:3, :3])) > 1e-30 else m[:3, :3]
    normals = corner.reshape(-1, 3)[tri_loops] @ normal_matrix.T
    normals /= np.maximum(np.linalg.norm(normals, axis=1, keepdims=True), 1e-30)
    positions = world[tri_verts].reshape(-1, 3, 3)
    fill = fill_class(positions) if n_tri else OPEN
    offset = 0.5 * (world.min(0) + world.max(0)) if len(world) else np.zeros(3)
    return SceneObject(obj_eval.name, key, (positions - offset).astype(np.float32),
                       normals.reshape(-1, 3, 3).astype(np.float32), 1.0, fill, offset=offset)


def visible_scene_objects(depsgraph: bpy.types.Depsgraph, view_layer: bpy.types.ViewLayer,
                          skip_baked: bool = False, only: set[str] | None = None,
                          cache: dict | None = None) -> list[SceneObject]:
    """Every visible mesh object of the view layer (or those named in `only`) as SceneObjects.
    skip_baked: objects carrying a baked AO map (BAKED_AO_PROPERTY) are drawn and occlude
    but get no HAO. cache: object name -> (key, SceneObject) of earlier looks (a viewport
    session's own; by default this module's)."""
    store = _DEFAULT_CACHE if cache is None else cache
    out = []
    seen = set()
    for obj in view_layer.objects:
        if obj.type != 'MESH' or not obj.visible_get(view_layer=view_layer):
            continue
        if only is not None and obj.name not in only:
            continue
        obj_eval = obj.evaluated_get(depsgraph)
        mesh = obj_eval.to_mesh()
        try:
            key = _key(obj_eval, mesh)
            cached = store.get(obj.name)
            if cached is None or cached[0] != key:
                cached = (key, _build(obj_eval, mesh, key))
                store[obj.name] = cached
        finally:
            obj_eval.to_mesh_clear()
        so = cached[1]
        so.receiver = 0.5 if (skip_baked and obj.get(BAKED_AO_PROPERTY)) else 1.0
        seen.add(obj.name)
        if len(so.positions):
            out.append(so)
    for name in list(store):
        if name not in seen and only is None:
            del store[name]
    return out


def clear_cache() -> None:
    _DEFAULT_CACHE.clear()


def camera_view_projection(camera: bpy.types.Object, depsgraph: bpy.types.Depsgraph,
                           width: int, height: int) -> np.ndarray:
    """(4, 4) world -> clip matrix of a scene camera for an image of width x height."""
    cam_eval = camera.evaluated_get(depsgraph)
    proj = np.array(cam_eval.calc_matrix_camera(depsgraph, x=width, y=height, scale_x=1.0, scale_y=1.0))
    view = np.array(cam_eval.matrix_world.inverted())
    return proj @ view


def region_box(props) -> tuple[np.ndarray, np.ndarray] | None:
    """The user's region of interest as a world box (lo, hi): a box object's bounds, or the
    bounds of a collection's objects; None means the bounds of the visible meshes."""
    objects = []
    if props.region_mode == 'BOX' and props.region_object is not None:
        objects = [props.region_object]
    elif props.region_mode == 'COLLECTION' and props.region_collection is not None:
        objects = list(props.region_collection.all_objects)
    corners = [obj.matrix_world @ mathutils.Vector(c) for obj in objects for c in obj.bound_box]
    if not corners:
        return None
    pts = np.array(corners, np.float64)
    return pts.min(0), pts.max(0)
