# SPDX-License-Identifier: GPL-3.0-or-later
"""Triangle soups from depsgraph-evaluated Blender objects (modifiers and armatures applied)."""
from __future__ import annotations

import bpy
import numpy as np

from ..core.errors import BakeInputError
from ..core.bake.vertex_target import VertexTarget, vertex_target
from ..core.geometry import TriangleSoup
from .mesh_arrays import corner_normals, loop_uvs, mesh_arrays

AO_UV_NAME = "AO_UV"


def evaluated_soup(obj: bpy.types.Object, depsgraph: bpy.types.Depsgraph, uv_name: str | None,
                   shading_normals: bool = True, alpha: bool = False, alpha_size: int = 4096,
                   matrix=None, name: str | None = None) -> TriangleSoup:
    """The object's evaluated mesh in world space, with the named UV map (or none) and, when
    asked, the corner shading normals and (alpha) what its materials let through as an
    occluder (blender/material_alpha.py). A mirroring transform (negative determinant) turns
    the triangles inside out; their corners are reordered so faces keep pointing outwards,
    as Blender and Cycles treat mirrored objects. alpha_size: the bake's resolution (alpha
    textures are read no finer than it can use). matrix, name: an instance's world transform
    and name (obj then the evaluated object it instances: blender/instances.py)."""
    obj_eval = obj if matrix is not None else obj.evaluated_get(depsgraph)
    mesh = obj_eval.to_mesh()
    try:
        co, tri_verts, tri_loops = mesh_arrays(mesh)
        m = np.array(obj_eval.matrix_world if matrix is None else matrix, dtype=np.float64)
        linear = m[:3, :3]
        if np.linalg.det(linear) < 0.0:
            tri_verts, tri_loops = tri_verts[:, ::-1], tri_loops[:, ::-1]
        world = co @ linear.T + m[:3, 3]
        uvs = loop_uvs(mesh, uv_name)[tri_loops] if uv_name else None
        normals = None
        if shading_normals and len(mesh.loops):
            _normals_at_unit_scale(mesh, co)
            # Normals transform with the inverse transpose (non-uniform scale bends them).
            normal_matrix = np.linalg.inv(linear).T if abs(np.linalg.det(linear)) > 1e-300 else linear
            normals = corner_normals(mesh)[tri_loops] @ normal_matrix.T
        lets_through = None
        if alpha:
            from .material_alpha import soup_alpha
            lets_through = soup_alpha(obj, mesh, tri_loops, alpha_size)
        return TriangleSoup(world[tri_verts], uvs, name=name or obj.name, normals=normals, alpha=lets_through)
    finally:
        obj_eval.to_mesh_clear()


# Blender computes normals in float32 with absolute thresholds: a mesh this small (or this
# large) gets garbage shading normals (a UV sphere of radius 1e-9: corners up to 169 degrees
# from their faces, a lone sphere baked down to 0.02 where it must read 1).
NORMALS_SCALE_RANGE = (1e-3, 1e6)


def _normals_at_unit_scale(mesh: bpy.types.Mesh, co: np.ndarray) -> None:
    """Scale a temporary mesh whose extent lies outside NORMALS_SCALE_RANGE to unit size, so
    that Blender evaluates its normals where float32 holds them (a uniform scale changes no
    normal, custom ones included). co: its (V, 3) vertex positions, read before."""
    extent = float(np.ptp(co, axis=0).max()) if len(co) else 0.0
    if extent > 0.0 and not NORMALS_SCALE_RANGE[0] <= extent <= NORMALS_SCALE_RANGE[1]:
        from mathutils import Matrix
        mesh.transform(Matrix.Diagonal((1.0 / extent,) * 3).to_4x4())


def corner_tangents(obj: bpy.types.Object, depsgraph: bpy.types.Depsgraph, uv_name: str) -> np.ndarray:
    """(F, 3, 4) float64 MikkTSpace tangent (world space) and bitangent sign of every corner of
    the evaluated mesh's UV map, in evaluated_soup's corner order: what Blender's Normal Map
    node decodes tangent-space maps with. A mirroring transform flips the sign (Blender's
    shader multiplies the bitangent by the object's negative-scale sign). Raises
    n-gons are triangulated on a copy first (MikkTSpace takes triangles and quads; Blender's
    own normal bake tessellates them too); quads and triangles keep their tangents."""
    obj_eval = obj.evaluated_get(depsgraph)
    mesh = obj_eval.to_mesh()
    try:
        _co, _tri_verts, tri_loops = mesh_arrays(mesh)
        linear = np.array(obj_eval.matrix_world, dtype=np.float64)[:3, :3]
        mirrored = np.linalg.det(linear) < 0.0
        if mirrored:
            tri_loops = tri_loops[:, ::-1]
        tangent, sign = _loop_tangents(mesh, uv_name)
        out = np.empty(tri_loops.shape + (4,))
        out[..., :3] = tangent[tri_loops] @ linear.T
        out[..., 3] = sign[tri_loops] * (-1.0 if mirrored else 1.0)
        return out
    finally:
        obj_eval.to_mesh_clear()


def _loop_tangents(mesh: bpy.types.Mesh, uv_name: str) -> tuple[np.ndarray, np.ndarray]:
    """((L, 3) float64 object-space MikkTSpace tangents, (L,) bitangent signs) of every loop;
    a mesh with n-gons through a copy whose n-gons are triangulated (n_gon_loop_tangents)."""
    sizes = np.empty(len(mesh.polygons), np.int64)
    mesh.polygons.foreach_get("loop_total", sizes)
    if len(sizes) and sizes.max() > 4:
        return n_gon_loop_tangents(mesh, uv_name)
    mesh.calc_tangents(uvmap=uv_name)
    try:
        return _read_tangents(mesh)
    finally:
        mesh.free_tangents()


def _read_tangents(mesh: bpy.types.Mesh) -> tuple[np.ndarray, np.ndarray]:
    tangent = np.empty(len(mesh.loops) * 3, np.float32)
    mesh.loops.foreach_get("tangent", tangent)
    sign = np.empty(len(mesh.loops), np.float32)
    mesh.loops.foreach_get("bitangent_sign", sign)
    return tangent.reshape(-1, 3).astype(np.float64), sign


# The face attribute that carries each polygon's index through the triangulated copy.
SOURCE_FACE = "hao_source_face"


def n_gon_loop_tangents(mesh: bpy.types.Mesh, uv_name: str) -> tuple[np.ndarray, np.ndarray]:
    """_loop_tangents of a mesh with n-gons: a copy with only its n-gons triangulated (bmesh)
    gets MikkTSpace tangents; each loop of the mesh takes those of a copy loop on the same
    vertex of the same source face (MikkTSpace welds corners of equal position, normal and
    UV, so inside a flat n-gon they agree). The mesh itself is not changed."""
    import bmesh

    bm = bmesh.new()
    try:
        bm.from_mesh(mesh)
        layer = bm.faces.layers.int.new(SOURCE_FACE)
        for face in bm.faces:
            face[layer] = face.index
        n_gons = [face for face in bm.faces if len(face.verts) > 4]
        bmesh.ops.triangulate(bm, faces=n_gons, quad_method='BEAUTY', ngon_method='EAR_CLIP')
        copy = bpy.data.meshes.new("hao_tangent_copy")
        bm.to_mesh(copy)
    finally:
        bm.free()
    try:
        copy.calc_tangents(uvmap=uv_name)
        tangent, sign = _read_tangents(copy)
        source = np.empty(len(copy.polygons), np.int64)
        copy.attributes[SOURCE_FACE].data.foreach_get("value", source)
        copy_keys = _face_vertex_keys(copy, source)
    finally:
        bpy.data.meshes.remove(copy)
    keys = _face_vertex_keys(mesh, np.arange(len(mesh.polygons)))
    order = np.argsort(copy_keys, kind="stable")
    match = order[np.searchsorted(copy_keys[order], keys)]
    return tangent[match], sign[match]


def _face_vertex_keys(mesh: bpy.types.Mesh, face_ids: np.ndarray) -> np.ndarray:
    """(L,) int64 one key per loop: its face's id (face_ids, per polygon) and its vertex."""
    starts = np.empty(len(mesh.polygons), np.int64)
    mesh.polygons.foreach_get("loop_start", starts)
    totals = np.empty(len(mesh.polygons), np.int64)
    mesh.polygons.foreach_get("loop_total", totals)
    loop_face = np.empty(len(mesh.loops), np.int64)
    loop_face[np.repeat(starts, totals) + _ranks(totals)] = np.repeat(face_ids, totals)
    verts = np.empty(len(mesh.loops), np.int64)
    mesh.loops.foreach_get("vertex_index", verts)
    return loop_face * (len(mesh.vertices) + 1) + verts


def _ranks(totals: np.ndarray) -> np.ndarray:
    """0, 1, ... within each run of the lengths totals: a polygon's loop offsets."""
    return np.arange(int(totals.sum())) - np.repeat(np.cumsum(totals) - totals, totals)


def extrusion_normals(obj: bpy.types.Object, depsgraph: bpy.types.Depsgraph) -> tuple[np.ndarray, np.ndarray]:
    """What Blender's Selected to Active pushes the cage along (render/intern/bake.cc):
    per evaluated triangle corner, the vertex normal on smooth faces and the face normal on
    flat ones, in object space (custom normals and sharp edges play no part), corners in
    evaluated_soup's order. Returns (normals (F, 3, 3), the object's linear map (3, 3))."""
    obj_eval = obj.evaluated_get(depsgraph)
    mesh = obj_eval.to_mesh()
    try:
        _co, tri_verts, _tri_loops = mesh_arrays(mesh)
        linear = np.array(obj_eval.matrix_world, dtype=np.float64)[:3, :3]
        if np.linalg.det(linear) < 0.0:
            tri_verts = tri_verts[:, ::-1]
        vertex_n = np.empty(len(mesh.vertices) * 3, np.float32)
        mesh.vertex_normals.foreach_get("vector", vertex_n)
        face_n = np.empty(len(mesh.polygons) * 3, np.float32)
        mesh.polygon_normals.foreach_get("vector", face_n)
        smooth = np.empty(len(mesh.polygons), bool)
        mesh.polygons.foreach_get("use_smooth", smooth)
        tri_face = np.empty(len(mesh.loop_triangles), np.int64)
        mesh.loop_triangles.foreach_get("polygon_index", tri_face)
        normals = vertex_n.reshape(-1, 3).astype(np.float64)[tri_verts]
        flat = ~smooth[tri_face]
        normals[flat] = face_n.reshape(-1, 3).astype(np.float64)[tri_face[flat]][:, None, :]
        return normals, linear
    finally:
        obj_eval.to_mesh_clear()


def color_attribute_target(obj: bpy.types.Object, depsgraph: bpy.types.Depsgraph, domain: str) -> VertexTarget:
    """The colour-attribute target of the object's evaluated mesh, corners in evaluated_soup's
    order, elements those of the original mesh (where the attribute is written). Raises
    BakeInputError where modifiers change the topology: Cycles maps such corners back
    through original indices the Python API does not expose."""
    obj_eval = obj.evaluated_get(depsgraph)
    mesh = obj_eval.to_mesh()
    try:
        _co, _tri_verts, tri_loops = mesh_arrays(mesh)
        if (len(mesh.vertices), len(mesh.loops)) != (len(obj.data.vertices), len(obj.data.loops)):
            raise BakeInputError(f"'{obj.name}': its modifiers change the mesh's vertices or corners, so the baked "
                                 f"values have no vertex of the mesh to go to; apply them, or bake an image")
        if np.linalg.det(np.array(obj_eval.matrix_world, dtype=np.float64)[:3, :3]) < 0.0:
            tri_loops = tri_loops[:, ::-1]
        loop_vertex = np.empty(len(mesh.loops), np.int64)
        mesh.loops.foreach_get("vertex_index", loop_vertex)
        return vertex_target(tri_loops, loop_vertex, domain, len(mesh.vertices))
    finally:
        obj_eval.to_mesh_clear()


def base_mesh_triangles(obj: bpy.types.Object) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Original (unevaluated) mesh: (positions (V, 3), triangles (F, 3), triangle loops (F, 3),
    each triangle's polygon (F,))."""
    co, tri_verts, tri_loops = mesh_arrays(obj.data)
    polygons = np.empty(len(obj.data.loop_triangles), dtype=np.int64)
    obj.data.loop_triangles.foreach_get("polygon_index", polygons)
    return co, tri_verts, tri_loops, polygons


def add_uv_layer(mesh: bpy.types.Mesh, name: str, tri_loops: np.ndarray, corner_uvs: np.ndarray) -> str:
    """Create a new UV map from per-triangle-corner UVs (F, 3, 2); returns its actual name.

    Loops shared by two triangles of one polygon receive the UV of the later triangle: the
    unwrap keeps a polygon's triangles in one chart (core/bake/charts.py), where the two
    agree; written_overlap measures what was written.
    The new map does not become the active one, so existing UV workflows are untouched.
    """
    active = mesh.uv_layers.active_index if len(mesh.uv_layers) else -1
    layer = mesh.uv_layers.new(name=name, do_init=False)
    if layer is None:
        raise BakeInputError(f"mesh '{mesh.name}' cannot take another UV map (Blender allows 8)")
    uv = np.zeros((len(mesh.loops), 2), dtype=np.float32)
    uv[tri_loops.ravel()] = corner_uvs.reshape(-1, 2)
    layer.uv.foreach_set("vector", uv.ravel())
    if active >= 0:
        mesh.uv_layers.active_index = active
    return layer.name


def written_triangle_uvs(mesh: bpy.types.Mesh, name: str, tri_loops: np.ndarray) -> np.ndarray:
    """(F, 3, 2): the named UV map as a bake reads it, per triangle corner (from the loops)."""
    return loop_uvs(mesh, name)[tri_loops]
