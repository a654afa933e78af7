# SPDX-License-Identifier: GPL-3.0-or-later
"""Ray-traced reference AO (CPU, mathutils' BVH), with the bakers' definitions.

accessibility(p, n) = 1 - E[rho(t)] over cosine-distributed directions about n (or uniform
ones for 'uniform' weighting), where t is the distance to the first hit and rho the falloff
of hao_addon.core.kernels. Directions are stratified (jittered grid on the concentric disk),
so with M rays the estimator's error is well below sqrt(A(1 - A)/M).

Self-intersection: each ray starts at p + n * offset with offset = 1e-6 of the scene's
bounding radius plus 1e-7 of |p| (float64 BVH; the scale term covers meshes far from the
origin), and hits closer than that are ignored. Back faces, when ignored, are skipped by
re-casting from just past the hit.
"""
from __future__ import annotations

import numpy as np
from mathutils import Vector
from mathutils.bvhtree import BVHTree

from .directions import frame_from_normal, stratified_cosine_hemisphere
from .geometry import face_normals_areas
from .kernels import occlusion_weight


def build_bvh(triangles: np.ndarray) -> BVHTree:
    """BVH over (F, 3, 3) triangles (a soup: vertices are not shared)."""
    verts = triangles.reshape(-1, 3).tolist()
    polys = np.arange(len(verts)).reshape(-1, 3).tolist()
    return BVHTree.FromPolygons(verts, polys, all_triangles=True, epsilon=0.0)


def uniform_hemisphere(count: int, rng: np.random.Generator) -> np.ndarray:
    """Stratified uniform directions about +z: cos(theta) uniform in [0, 1]. (n, 3)."""
    side = max(1, int(np.sqrt(count)))
    gy, gx = np.meshgrid(np.arange(side), np.arange(side), indexing="ij")
    u = (gx.ravel() + rng.random(side * side)) / side
    v = (gy.ravel() + rng.random(side * side)) / side
    z = u
    r = np.sqrt(np.clip(1.0 - z * z, 0.0, 1.0))
    return np.stack([r * np.cos(2 * np.pi * v), r * np.sin(2 * np.pi * v), z], axis=1)


def first_hit(ray_cast, origin: Vector, direction: np.ndarray, reach: float, offset: float,
              face_normals: np.ndarray | None, min_distance: float = 0.0, dv: Vector | None = None) -> float:
    """Distance along `direction` (3,) from `origin` to the first hit within `reach` (inf if
    none); faces whose normal points along the ray (seen from behind) are skipped when
    face_normals (F, 3) is given (back faces ignored), and hits nearer than min_distance.
    dv: `direction` as a Vector, where the caller has made it once for many rays."""
    dv = Vector(direction) if dv is None else dv
    o = origin
    travelled = 0.0
    for _ in range(32):  # back-face skips
        loc, _n, idx, dist = ray_cast(o, dv, reach - travelled)
        if loc is None:
            return np.inf
        travelled += dist
        if (face_normals is not None and float(face_normals[idx] @ direction) > 0.0) or travelled < min_distance:
            o = loc + dv * offset  # a back face, or too near: skip it and continue
            continue
        return travelled
    return np.inf


def first_hits(ray_cast, origins: list[Vector], direction: np.ndarray, reach: float, offsets: np.ndarray,
               face_normals: np.ndarray | None, min_distance: float = 0.0) -> np.ndarray:
    """(n,) first_hit of each of `origins` along one `direction` (3,), offsets (n,) their
    self-intersection offsets. Without back faces to skip or a min distance every ray is one
    cast, so that loop calls the BVH directly (the same distances; the reference's time is
    mostly this loop's)."""
    dv = Vector(direction)
    if face_normals is not None or min_distance > 0.0:
        return _distances([first_hit(ray_cast, o, direction, reach, offset, face_normals, min_distance, dv)
                           for o, offset in zip(origins, offsets)])
    return _distances([ray_cast(o, dv, reach)[3] for o in origins])


def first_hits_from(ray_cast, origin: Vector, directions: np.ndarray, reach: float, offset: float,
                    face_normals: np.ndarray | None) -> np.ndarray:
    """(n,) first_hit from one `origin` along each of `directions` (n, 3); without back faces
    to skip each ray is one cast, made directly (the same distances)."""
    if face_normals is not None:
        return _distances([first_hit(ray_cast, origin, d, reach, offset, face_normals) for d in directions])
    return _distances([ray_cast(origin, Vector(d), reach)[3] for d in directions.tolist()])


def _distances(dists: list) -> np.ndarray:
    """(n,) float64 of hit distances, a miss (None from the BVH) as inf."""
    return np.array([np.inf if d is None else d for d in dists], dtype=np.float64).reshape(len(dists))


def hits_along(ray_cast, origin: Vector, direction: np.ndarray, reach: float, offset: float,
               face_normals: np.ndarray | None, opaque, limit: int = 256,
               min_distance: float = 0.0) -> list[tuple[float, int, np.ndarray]]:
    """Every surface along `direction` from `origin` within `reach`, nearest first, up to the
    first one opaque(face index, hit point) says stops the ray: (distance, face index, hit
    point (3,)); back faces skipped as first_hit skips them."""
    dv = Vector(direction)
    o = origin
    travelled = 0.0
    out = []
    for _ in range(limit):
        loc, _n, idx, dist = ray_cast(o, dv, reach - travelled)
        if loc is None:
            break
        travelled += dist
        o = loc + dv * offset
        if (face_normals is not None and float(face_normals[idx] @ direction) > 0.0) or travelled < min_distance:
            continue
        point = np.array(loc[:])
        out.append((travelled, idx, point))
        if opaque(idx, point):
            break
    return out


def ray_offset(point: np.ndarray, scene_radius: float) -> float:
    """How far a ray starts off the surface at `point` (3,): see the module docstring."""
    return 1e-6 * scene_radius + 1e-7 * float(np.abs(point).max())


def reference_accessibility(points: np.ndarray, normals: np.ndarray, triangles: np.ndarray,
                            rays: int = 1024, max_distance: float = 0.0, falloff: str = "none",
                            weighting: str = "cosine", ignore_back_faces: bool = False,
                            seed: int = 0, bvh: BVHTree | None = None,
                            geometric_normals: np.ndarray | None = None) -> np.ndarray:
    """Accessibility at surface points.

    points, normals: (n, 3), normals the shading normals the hemisphere is about;
    triangles: (F, 3, 3) the whole occluding scene (the receivers included).
    geometric_normals: (n, 3) the true surface's normals where they differ (None: the same):
    rays start off that surface, and directions below it count as occluded (Cycles' AO pass
    traces only directions above the geometric normal). Returns (n,) float64 in [0, 1].
    """
    points = np.asarray(points, dtype=np.float64)
    normals = np.asarray(normals, dtype=np.float64)
    true_normals = normals if geometric_normals is None else np.asarray(geometric_normals, np.float64)
    bvh = bvh or build_bvh(triangles)
    flat = triangles.reshape(-1, 3)
    radius = float(np.linalg.norm(flat.max(0) - flat.min(0))) / 2.0
    face_n, _ = face_normals_areas(triangles) if ignore_back_faces else (None, None)
    rng = np.random.default_rng(seed)
    frames = frame_from_normal(normals)
    reach = max_distance if max_distance > 0.0 else 1e30
    out = np.empty(len(points))
    ray_cast = bvh.ray_cast
    for i in range(len(points)):
        local = stratified_cosine_hemisphere(rays, rng) if weighting == "cosine" else uniform_hemisphere(rays, rng)
        world = local @ frames[i]
        offset = ray_offset(points[i], radius)
        origin = Vector(points[i] + true_normals[i] * offset)
        above = world @ true_normals[i] > 0.0
        dists = np.zeros(len(world))  # below the true surface: occluded at once
        dists[above] = first_hits_from(ray_cast, origin, world[above], reach, offset, face_n)
        out[i] = 1.0 - occlusion_weight(dists, max_distance, falloff).mean()
    return out
