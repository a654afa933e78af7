# SPDX-License-Identifier: GPL-3.0-or-later
"""High-to-low projection (Cycles' Selected to Active): which point of the high-poly sources
each texel sample of the low-poly target stands for.

As Blender's bake does it (render/intern/bake.cc, RE_bake_pixels_populate_from_objects):
- without a cage object the ray starts at the low-poly point pushed out by the cage
  extrusion along the low-poly's normal (vertex normals interpolated on smooth faces, the
  face normal on flat ones; custom normals play no part) and points back along -normal;
- with a cage object (same triangles as the target) it starts at the cage's point of the
  same barycentric coordinates and points towards the low-poly point;
- the nearest hit of any source, front or back face, wins; with a max ray distance > 0 a
  hit farther than that from the ray's start is a miss. A sample that misses gets no value.
One ray per sample, once per bake (here with mathutils' BVH, about 2.5 us a ray; the GPU
bakers cast with its twin gpu/bake_ray_cast.py, bakers.ray_caster_for; the passes then bake
the hit points like any other receivers), in steps of RAYS_PER_STEP rays: the *_steps
generators yield the fraction cast after each, so a modal bake can draw progress and be
cancelled during a projection of seconds.
"""
from __future__ import annotations

import time
from itertools import repeat
from operator import itemgetter
from dataclasses import dataclass
from typing import Callable, Generator

import numpy as np

from ..errors import BakeInputError
from ..geometry import TriangleSoup, corner_shading_normals, face_normals_areas, smooth_vertex_normals
from ..steps import drain
from .receivers import Receivers, interpolate_unit, tiled_sample_points
from .udim import UdimLayout
from .settings import BakeSettings
from .terminator import smooth_surface_lift

# Warn when more than this fraction of the sampled texels found no high-poly surface (they
# are filled from their neighbours, as margin).
MISSED_TEXELS_WARNING = 0.01
# A ray must start where float32 positions (the GPU's) still resolve this share of the mesh's
# size: the spacing of float32 numbers at the start, |p| + extrusion, is |p| x 2^-23.
EXTRUSION_RESOLUTION = 1e-4
FLOAT32_SPACING = 2.0 ** -23


@dataclass
class HighToLow:
    """A Selected-to-Active request. sources: the high-poly meshes (world space, with their
    shading normals where they have them). extrusion_normals: (Ft, 3, 3) the direction the
    cage extrusion pushes each target corner, in the low-poly's object space (None: Blender's
    smooth vertex normals of the target, low_linear the identity). cage: (Ft, 3, 3) world
    corners of a cage object with the target's triangles, or None. The cage extrusion and max ray distance are bake settings (core/bake/settings.py)."""

    sources: list[TriangleSoup]
    extrusion_normals: np.ndarray | None = None
    cage: np.ndarray | None = None
    cage_name: str = "cage"
    # The low-poly's object-to-world linear map (3, 3). Blender extrudes in object space
    # (normalized object-space normal times the extrusion, then transformed), so on a scaled
    # object the extrusion scales too; extrusion_normals are then object-space normals.
    low_linear: np.ndarray | None = None


def check_high_to_low(target: TriangleSoup, request: HighToLow, cage_extrusion: float = 0.0) -> None:
    """Raise BakeInputError for a request that cannot be baked (cage_extrusion: the setting,
    refused where float32 ray starts would lose the mesh's detail)."""
    check_extrusion(target, request, cage_extrusion)
    if not request.sources or not any(s.face_count for s in request.sources):
        raise BakeInputError(f"Selected to Active needs a high-poly source with faces besides '{target.name}'")
    for source in request.sources:
        if not np.isfinite(source.positions).all():
            raise BakeInputError(f"'{source.name}' has NaN or infinite vertex positions")
    if request.cage is not None:
        if request.cage.shape != target.positions.shape:
            raise BakeInputError(f"the cage '{request.cage_name}' has {len(request.cage)} triangles, "
                                 f"'{target.name}' has {target.face_count}: a cage must be a copy of the "
                                 f"low-poly with moved vertices")
        if not np.isfinite(request.cage).all():
            raise BakeInputError(f"the cage '{request.cage_name}' has NaN or infinite vertex positions")


def max_extrusion(target: TriangleSoup, request: HighToLow) -> float:
    """The largest cage extrusion whose ray starts float32 positions hold to EXTRUSION_RESOLUTION
    of the low-poly's size (bounding-box diagonal; the object's scale included, as Blender
    extrudes in object space)."""
    low, high = target.positions.min(axis=(0, 1)), target.positions.max(axis=(0, 1))
    size = float(np.linalg.norm(high - low))
    reach = float(np.abs(target.positions).max())
    gain = 1.0 if request.low_linear is None else float(np.linalg.norm(request.low_linear, 2))
    return max(size * EXTRUSION_RESOLUTION / FLOAT32_SPACING - reach, 0.0) / max(gain, 1e-30)


def check_extrusion(target: TriangleSoup, request: HighToLow, cage_extrusion: float) -> None:
    """Refuse a cage extrusion beyond max_extrusion (with a cage object it is not used)."""
    if request.cage is not None or cage_extrusion <= 0.0:
        return
    limit = max_extrusion(target, request)
    if cage_extrusion > limit:
        raise BakeInputError(f"a cage extrusion of {cage_extrusion:g} is too far for '{target.name}': float32 ray "
                             f"starts there cannot resolve a mesh of its size; use at most {limit:.4g} (or a "
                             f"cage object)")


def ray_starts(target: TriangleSoup, request: HighToLow, face: np.ndarray, bary: np.ndarray,
               cage_extrusion: float) -> tuple[np.ndarray, np.ndarray]:
    """(origins (m, 3), unit directions (m, 3)) world, of the samples at (face (m,), bary (m, 3))."""
    low = np.einsum("mk,mkd->md", bary, target.positions[face])
    if request.cage is not None:
        origins = np.einsum("mk,mkd->md", bary, request.cage[face])
        d = low - origins
    else:
        normals = request.extrusion_normals
        linear = np.eye(3) if request.low_linear is None else np.asarray(request.low_linear, np.float64)
        if normals is None:
            normals = smooth_vertex_normals(target.positions)
            linear = np.eye(3)
        n = np.einsum("mk,mkd->md", bary, normals[face])
        n /= np.maximum(np.linalg.norm(n, axis=1, keepdims=True), 1e-30)
        origins = low + (n @ linear.T) * cage_extrusion
        # Normals map to world space with the inverse transpose.
        d = -(n @ np.linalg.inv(linear)) if abs(np.linalg.det(linear)) > 1e-300 else -(n @ linear.T)
    length = np.linalg.norm(d, axis=1, keepdims=True)
    return origins, np.divide(d, length, out=np.zeros_like(d), where=length > 0.0)


# Rays cast between two progress steps (about 0.1-0.2 s here).
RAYS_PER_STEP = 50_000


def project(origins: np.ndarray, directions: np.ndarray, triangles: np.ndarray, max_ray_distance: float
            ) -> tuple[np.ndarray, np.ndarray]:
    """First hit of each ray on triangles (Fs, 3, 3) (both sides). Returns (face (m,) int64,
    -1 for a miss or a zero direction; bary (m, 3) float64 of the hit point on that face)."""
    return drain(project_steps(origins, directions, triangles, max_ray_distance))


def project_steps(origins: np.ndarray, directions: np.ndarray, triangles: np.ndarray, max_ray_distance: float
                  ) -> Generator[float, None, tuple[np.ndarray, np.ndarray]]:
    """project(), yielding the fraction of rays cast after every RAYS_PER_STEP of them."""
    from mathutils.bvhtree import BVHTree  # numpy core otherwise; mathutils comes with bpy

    verts = triangles.reshape(-1, 3).tolist()
    bvh = BVHTree.FromPolygons(verts, np.arange(len(verts)).reshape(-1, 3).tolist(), all_triangles=True, epsilon=0.0)
    reach = max_ray_distance if max_ray_distance > 0.0 else 1e30
    ray_cast = bvh.ray_cast
    usable = np.flatnonzero(np.abs(directions).sum(axis=1) > 0.0)
    # Only the casts run per ray in Python; each step's face indices and distances are read
    # into arrays at once (a miss is (None, None, None, None): NaN as a float), and the point
    # is origin + distance * direction (storing each hit Vector into a numpy row cost about as
    # much as the cast itself).
    face = np.full(len(origins), -1, np.int64)
    distance = np.zeros(len(origins))
    for start in range(0, len(usable), RAYS_PER_STEP):
        chunk = usable[start:start + RAYS_PER_STEP]
        hits = list(map(ray_cast, origins[chunk].tolist(), directions[chunk].tolist(), repeat(reach, len(chunk))))
        index = np.fromiter(map(itemgetter(2), hits), np.float64, len(hits))
        found = ~np.isnan(index)
        face[chunk[found]] = index[found]
        distance[chunk[found]] = np.fromiter(map(itemgetter(3), hits), np.float64, len(hits))[found]
        yield (start + len(chunk)) / len(usable)
    points = origins + directions * distance[:, None]
    hit = face >= 0
    bary = np.zeros((len(origins), 3))
    bary[hit] = barycentric(points[hit], triangles[face[hit]])
    return face, bary


def barycentric(points: np.ndarray, triangles: np.ndarray) -> np.ndarray:
    """(m, 3) barycentric coordinates of points (m, 3) in triangles (m, 3, 3), clipped to the
    triangle (the BVH's float32 hit can lie a hair outside)."""
    a, b, c = triangles[:, 0], triangles[:, 1], triangles[:, 2]
    e1, e2, p = b - a, c - a, points - a
    d11 = np.einsum("md,md->m", e1, e1)
    d12 = np.einsum("md,md->m", e1, e2)
    d22 = np.einsum("md,md->m", e2, e2)
    p1 = np.einsum("md,md->m", p, e1)
    p2 = np.einsum("md,md->m", p, e2)
    det = d11 * d22 - d12 * d12
    safe = np.where(np.abs(det) > 0.0, det, 1.0)
    v = (d22 * p1 - d12 * p2) / safe
    w = (d11 * p2 - d12 * p1) / safe
    return barycentric_from_uv(np.stack([v, w], axis=1))


def barycentric_from_uv(uv: np.ndarray) -> np.ndarray:
    """(m, 3) barycentric coordinates (1 - u - v, u, v) of uv (m, 2), clipped to the triangle
    and renormalized (a float32 hit can lie a hair outside its edges)."""
    out = np.clip(np.stack([1.0 - uv[:, 0] - uv[:, 1], uv[:, 0], uv[:, 1]], axis=1), 0.0, 1.0)
    return out / np.maximum(out.sum(axis=1, keepdims=True), 1e-30)


# A ray cast: project_steps' signature (origins, directions, triangles, max ray distance),
# a generator of progress fractions that returns (face, bary). bakers.ray_caster_for() gives
# the GPU twin (gpu/bake_ray_cast.py) to the GPU bakers.
RayCast = Callable[[np.ndarray, np.ndarray, np.ndarray, float], Generator[float, None, tuple[np.ndarray, np.ndarray]]]
# A batch of rays' first hits (reference_baker.ReferenceBaker.run_directions): origins (m, 3),
# unit directions (m, 3), triangles (F, 3, 3), reach -> (m,) distances, inf where none.
DistanceCast = Callable[[np.ndarray, np.ndarray, np.ndarray, float], np.ndarray]


def projected_receivers_steps(target: TriangleSoup, request: HighToLow, settings: BakeSettings,
                              centre: np.ndarray, scale: float, cast: RayCast | None = None,
                              tiles: UdimLayout | None = None
                              ) -> Generator[float, None, tuple[Receivers, dict, str | None]]:
    """The receivers of a Selected-to-Active bake: the source points the target's texel
    samples project to (rays cast by `cast`, default project_steps), with the sources' own
    shading normals (settings.normals), weight scale 1 (each is normalized by its own weight
    sum: estimators.texel_sums), positions normalized by (centre (3,), scale). Returns them,
    stats, and a warning when many texels found nothing."""
    texel, face, bary = tiled_sample_points(target.uvs, settings.size, settings.sample_count, tiles)
    origins, rays = ray_starts(target, request, face, bary, settings.cage_extrusion)
    triangles = np.concatenate([s.positions for s in request.sources])
    started = time.perf_counter()
    hit_face, hit_bary = yield from (cast or project_steps)(origins, rays, triangles, settings.max_ray_distance)
    seconds = time.perf_counter() - started
    hit = hit_face >= 0
    hf, hb = hit_face[hit], hit_bary[hit]
    mesh = settings.normals == "mesh"
    face_normals, _ = face_normals_areas(triangles)
    starts = np.cumsum([0] + [s.face_count for s in request.sources])
    corners = np.concatenate([corner_shading_normals(s.positions, s.normals if mesh else None, face_normals[a:b])[0]
                              for s, a, b in zip(request.sources, starts[:-1], starts[1:])])
    shading = interpolate_unit(corners, hf, hb)
    geometric = face_normals[hf]
    points = (np.einsum("mk,mkd->md", hb, triangles[hf]) - centre) / scale
    smooth = int((np.einsum("md,md->m", shading, geometric) < 1.0 - 1e-6).sum())
    lift = None
    if smooth and settings.terminator_offset > 0.0:  # Cycles lifts the high-poly's ray starts too
        lift = smooth_surface_lift(triangles[hf], corners[hf].astype(np.float64), hb, geometric) / scale
    receivers = Receivers(points, geometric, shading, np.ones(len(points)), texel[hit], lift)
    cells = settings.size * settings.size * (1 if tiles is None else tiles.count)
    sampled = int((np.bincount(texel, minlength=cells) > 0).sum())
    missed = sampled - int((np.bincount(receivers.texel, minlength=cells) > 0).sum())
    warning = None
    if sampled and missed == sampled:
        raise BakeInputError(f"none of the {sampled} texels of '{target.name}' found a high-poly surface: check "
                             f"that the high-poly lies on the low-poly, and raise the cage extrusion or the max "
                             f"ray distance, or use a cage object")
    if sampled and missed > MISSED_TEXELS_WARNING * sampled:
        warning = (f"{missed} of {sampled} texels of '{target.name}' ({100.0 * missed / sampled:.1f} %) found no "
                   f"high-poly surface and were filled from their neighbours: raise the cage extrusion or the max "
                   f"ray distance, or use a cage object")
    stats = dict(high_poly_faces=int(len(triangles)), projected_samples=int(len(texel)),
                 missed_samples=int((~hit).sum()), missed_texels=int(missed), projection_seconds=round(seconds, 3),
                 smooth_receivers=smooth)
    return receivers, stats, warning
