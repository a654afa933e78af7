# SPDX-License-Identifier: GPL-3.0-or-later
"""Sphere proxies on Blender meshes: Lloyd clustering of the rest pose stored as mesh
attributes, and per-frame spheres from the depsgraph-evaluated (deformed) vertices.

Storage (saved with the .blend, visible in the spreadsheet): the integer point attribute
CLUSTER_ATTRIBUTE (cluster of each vertex) and the float point attribute WEIGHT_ATTRIBUTE
(its area weight in the rest pose); the sphere count on the mesh (K_PROPERTY).
Per frame only objects whose evaluated vertices changed are recomputed (`stats`)."""
from __future__ import annotations

import bpy
import numpy as np

from ..core.proxies.lloyd import ProxyError, check_radii, lloyd_clusters, sphere_proxies, vertex_areas
from .mesh_arrays import read_positions

CLUSTER_ATTRIBUTE = "hao_sphere_cluster"
WEIGHT_ATTRIBUTE = "hao_sphere_weight"
K_PROPERTY = "hao_sphere_count"
SETTINGS_PROPERTY = "hao_sphere_settings"  # on the object: what the last sync used

stats = {"synced": 0, "reused": 0}
# name -> (evaluated vertices, world matrix, centres, radii) of the last update
_cache: dict[str, tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]] = {}


def has_armature(obj: bpy.types.Object) -> bool:
    return any(m.type == 'ARMATURE' and m.object is not None for m in obj.modifiers)


def has_proxies(obj: bpy.types.Object) -> bool:
    return obj.type == 'MESH' and CLUSTER_ATTRIBUTE in obj.data.attributes and K_PROPERTY in obj.data


def make_proxies(obj: bpy.types.Object, count: int, seed: int = 0, max_iterations: int = 100) -> dict:
    """Cluster the rest pose (the mesh datablock itself, before modifiers) into `count`
    spheres and store the result on the mesh. Raises ProxyError on bad input, before
    anything is changed."""
    if obj is None or obj.type != 'MESH':
        raise ProxyError("sphere proxies need a mesh object")
    if not has_armature(obj):
        raise ProxyError(f"'{obj.name}' has no Armature modifier: sphere proxies follow armature deformation; "
                         "static meshes are covered by HAO's voxels")
    mesh = obj.data
    co = np.empty(len(mesh.vertices) * 3, np.float64)
    mesh.vertices.foreach_get("co", co)
    mesh.calc_loop_triangles()
    tris = np.empty(len(mesh.loop_triangles) * 3, np.int64)
    mesh.loop_triangles.foreach_get("vertices", tris)
    verts = co.reshape(-1, 3)
    weights = vertex_areas(verts, tris.reshape(-1, 3))
    clustering = lloyd_clusters(verts, weights, count, seed=seed, max_iterations=max_iterations)
    _, radii = sphere_proxies(verts, clustering.labels, weights, count)
    check_radii(radii)
    for name, kind, values in ((CLUSTER_ATTRIBUTE, 'INT', clustering.labels.astype(np.int32)),
                               (WEIGHT_ATTRIBUTE, 'FLOAT', weights.astype(np.float32))):
        if name in mesh.attributes:
            mesh.attributes.remove(mesh.attributes[name])
        attr = mesh.attributes.new(name, kind, 'POINT')
        attr.data.foreach_set("value", values)
    mesh[K_PROPERTY] = int(count)
    obj[SETTINGS_PROPERTY] = {"count": int(count), "seed": int(seed), "max_iterations": int(max_iterations)}
    _cache.pop(obj.name, None)
    return dict(iterations=clustering.iterations, converged=clustering.converged, energy=clustering.energies[-1])


def clear_proxies(obj: bpy.types.Object) -> None:
    mesh = obj.data
    for name in (CLUSTER_ATTRIBUTE, WEIGHT_ATTRIBUTE):
        if name in mesh.attributes:
            mesh.attributes.remove(mesh.attributes[name])
    if K_PROPERTY in mesh:
        del mesh[K_PROPERTY]
    if SETTINGS_PROPERTY in obj:
        del obj[SETTINGS_PROPERTY]
    _cache.pop(obj.name, None)


def _read_attribute(mesh, name, dtype) -> np.ndarray:
    values = np.empty(len(mesh.vertices), dtype)
    mesh.attributes[name].data.foreach_get("value", values)
    return values


def object_spheres(obj: bpy.types.Object, depsgraph: bpy.types.Depsgraph) -> tuple[np.ndarray, np.ndarray]:
    """World-space (centres (K, 3), radii (K,)) of the object's proxies in the evaluated pose.

    Work per frame: one read of the evaluated vertices (the depsgraph's mesh, no copy), one
    comparison with the last frame's (memcmp speed), and only when they differ the sphere
    update, in object space (see core.proxies.lloyd.sphere_proxies), then K centres to world space.
    Radii scale by the largest axis scale of the object (exact for uniform scale)."""
    mesh = obj.data
    obj_eval = obj.evaluated_get(depsgraph)
    emesh = obj_eval.data
    co = read_positions(emesh)
    m = np.array(obj_eval.matrix_world, np.float64)
    cached = _cache.get(obj.name)
    if cached is not None and np.array_equal(cached[0], co) and np.array_equal(cached[1], m):
        stats["reused"] += 1
        return cached[2], cached[3]
    labels = _read_attribute(mesh, CLUSTER_ATTRIBUTE, np.int32)
    if len(co) // 3 != len(labels):
        raise ProxyError(f"'{obj.name}' now has {len(co) // 3} vertices but its sphere proxies were made for "
                         f"{len(labels)} (a modifier changed the topology): sync the sphere proxies again")
    weights = _read_attribute(mesh, WEIGHT_ATTRIBUTE, np.float32)
    local_centres, local_radii = sphere_proxies(co.reshape(-1, 3), labels, weights, int(mesh[K_PROPERTY]))
    centres = local_centres @ m[:3, :3].T + m[:3, 3]
    radii = local_radii * float(np.linalg.norm(m[:3, :3], axis=0).max())
    _cache[obj.name] = (co, m, centres, radii)
    stats["synced"] += 1
    return centres, radii


def scene_spheres(view_layer: bpy.types.ViewLayer, depsgraph) -> tuple[tuple[np.ndarray, np.ndarray] | None, set]:
    """All visible objects' proxies concatenated, and the names of the objects that have them."""
    parts, names = [], set()
    for obj in view_layer.objects:
        if obj.type == 'MESH' and obj.visible_get(view_layer=view_layer) and has_proxies(obj):
            parts.append(object_spheres(obj, depsgraph))
            names.add(obj.name)
    if not parts:
        return None, names
    return (np.concatenate([p[0] for p in parts]), np.concatenate([p[1] for p in parts])), names
