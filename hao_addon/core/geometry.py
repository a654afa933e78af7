# SPDX-License-Identifier: GPL-3.0-or-later
"""Triangle-soup geometry shared by the bakers and the references (float64 numpy)."""
from __future__ import annotations

import hashlib
from collections import OrderedDict
from dataclasses import dataclass

import numpy as np

from .components import root_labels


@dataclass
class TriangleSoup:
    """Triangles in world space, unshared vertices.

    positions: (F, 3, 3) float64 world-space corners.
    uvs: (F, 3, 2) float64 UV corners in [0, 1] (targets only; None for pure occluders).
    name: label for messages.
    normals: (F, 3, 3) float64 shading normals at the corners, as the mesh is shaded (smooth,
    sharp edges, custom normals), world space; None: flat (the face normals).
    alpha: how much light each face stops as an occluder (core/bake/alpha.SoupAlpha), or
    None: opaque.
    """

    positions: np.ndarray
    uvs: np.ndarray | None = None
    name: str = "mesh"
    normals: np.ndarray | None = None
    alpha: object = None  # core/bake/alpha.SoupAlpha | None

    def __post_init__(self) -> None:
        self.positions = np.asarray(self.positions, dtype=np.float64).reshape(-1, 3, 3)
        if self.uvs is not None:
            self.uvs = np.asarray(self.uvs, dtype=np.float64).reshape(-1, 3, 2)
            if len(self.uvs) != len(self.positions):
                raise ValueError(f"{self.name}: {len(self.uvs)} UV triangles for {len(self.positions)} triangles")
        if self.normals is not None:
            self.normals = np.asarray(self.normals, dtype=np.float64).reshape(-1, 3, 3)
            if len(self.normals) != len(self.positions):
                raise ValueError(f"{self.name}: {len(self.normals)} normal triangles for {len(self.positions)} triangles")

    @property
    def face_count(self) -> int:
        return len(self.positions)


def face_normals_areas(positions: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Unit face normals (F, 3) and areas (F,) of (F, 3, 3) triangles.

    Degenerate (zero-area) triangles get a zero normal and zero area instead of NaN.
    The winding is counter-clockwise: n = (b - a) x (c - a).
    """
    a, b, c = positions[:, 0], positions[:, 1], positions[:, 2]
    ab, ac = b - a, c - a
    cross = np.cross(ab, ac)
    length = np.sqrt(np.einsum("ij,ij->i", cross, cross))
    # Relative threshold: an area tiny against the triangle's own edge lengths is noise.
    # Elementwise over the columns: numpy reductions over an axis of length 3 are ~10x slower.
    edge = np.abs(ab[:, 0])
    for column in (ab[:, 1], ab[:, 2], ac[:, 0], ac[:, 1], ac[:, 2]):
        np.maximum(edge, np.abs(column), out=edge)
    np.maximum(edge, 1e-300, out=edge)
    valid = length > 1e-12 * edge * edge
    normals = np.zeros_like(cross)
    normals[valid] = cross[valid] / length[valid, None]
    return normals, np.where(valid, 0.5 * length, 0.0)


def corner_shading_normals(positions: np.ndarray, normals: np.ndarray | None,
                           face_normals: np.ndarray) -> tuple[np.ndarray, int]:
    """Unit shading normals (F, 3, 3) of (F, 3, 3) triangles from the corner normals a mesh
    carries (or None: flat), and how many corners differ from their face's normal.

    A corner normal that is zero, not finite, or on a zero-area face falls back to the face
    normal (Blender writes such normals for degenerate faces; a NaN must not reach a shader).
    """
    flat = np.repeat(np.asarray(face_normals, np.float64)[:, None, :], 3, axis=1)
    if normals is None:
        return flat, 0
    n = np.asarray(normals, np.float64).reshape(-1, 3, 3)
    length = np.sqrt(np.einsum("fki,fki->fk", n, n))
    good = np.isfinite(length) & (length > 1e-12) & (np.abs(face_normals).sum(axis=1) > 0.0)[:, None]
    unit = np.where(good[..., None], n / np.where(good, length, 1.0)[..., None], flat)
    # float32 shaders cannot tell apart normals this close: such a corner is flat.
    differs = np.einsum("fki,fki->fk", unit, flat) < 1.0 - 1e-6
    return unit, int(differs.sum())


def unusable_normal_warnings(name: str, normals: np.ndarray | None) -> list[str]:
    """[] or a warning that some of a mesh's (F, 3, 3) corner normals are zero or not finite
    (corner_shading_normals bakes their faces flat there)."""
    if normals is None:
        return []
    n = np.asarray(normals, np.float64).reshape(-1, 3)
    length = np.sqrt(np.einsum("ki,ki->k", n, n))
    bad = int((~np.isfinite(length) | (length <= 1e-12)).sum())
    if bad == 0:
        return []
    return [f"'{name}': {bad} of its {len(n)} shading normals are zero or not finite (a degenerate mesh, or one "
            f"at an extreme scale): those corners are shaded flat, with their faces' normals"]


def smooth_vertex_normals(positions: np.ndarray) -> np.ndarray:
    """(F, 3, 3) corner normals of (F, 3, 3) triangles shaded smooth the way Blender does it:
    at each welded vertex the face normals weighted by the corner angle, normalized."""
    verts, tri = _welded_triangles(positions)
    p = verts[tri]  # (F, 3, 3)
    face_n, _ = face_normals_areas(p)
    angle = np.empty(tri.shape)
    for k in range(3):
        e1 = p[:, (k + 1) % 3] - p[:, k]
        e2 = p[:, (k + 2) % 3] - p[:, k]
        cos = np.einsum("fi,fi->f", e1, e2) / np.maximum(
            np.linalg.norm(e1, axis=1) * np.linalg.norm(e2, axis=1), 1e-300)
        angle[:, k] = np.arccos(np.clip(cos, -1.0, 1.0))
    sums = np.zeros((len(verts), 3))
    np.add.at(sums, tri.ravel(), (face_n[:, None, :] * angle[..., None]).reshape(-1, 3))
    length = np.linalg.norm(sums, axis=1, keepdims=True)
    vertex_n = np.divide(sums, length, out=np.zeros_like(sums), where=length > 1e-300)
    return vertex_n[tri]


def uv_areas(uvs: np.ndarray) -> np.ndarray:
    """Unsigned UV-space areas (F,) of (F, 3, 2) UV triangles (in units of the unit square)."""
    d1 = uvs[:, 1] - uvs[:, 0]
    d2 = uvs[:, 2] - uvs[:, 0]
    return 0.5 * np.abs(d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0])


def column_bounds(points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """lo (3,) and hi (3,) corners of the box of points (n, 3).

    Column by column: numpy reductions down the columns of an (n, 3) array, or over an axis
    of length 3, are ~20x slower (16 ms -> 0.8 ms for the bunny's 208k corners)."""
    return (np.array([points[:, k].min() for k in range(3)]),
            np.array([points[:, k].max() for k in range(3)]))


def bounding_sphere(points: np.ndarray) -> tuple[np.ndarray, float]:
    """Centre (3,) and radius of a sphere enclosing points (n, 3): the box centre and
    the farthest point from it (within sqrt(3) of optimal, always enclosing)."""
    pts = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    lo, hi = column_bounds(pts)
    centre = 0.5 * (lo + hi)
    squared = (pts[:, 0] - centre[0]) ** 2
    squared += (pts[:, 1] - centre[1]) ** 2
    squared += (pts[:, 2] - centre[2]) ** 2
    return centre, float(np.sqrt(squared.max()))



def weld(points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Merge bit-identical points (n, 3) float64: (first (V,) index of each distinct point,
    inverse (n,) its number per point), numbered in order of a 64-bit hash of the bits.

    A sort of hashes instead of np.unique over rows (4x faster: 15 ms for 200k corners); the
    result is checked exactly and recomputed by rows in the (never seen) case of a collision.
    """
    pts = np.ascontiguousarray(np.asarray(points, dtype=np.float64).reshape(-1, 3))
    bits = pts.view(np.uint64)
    with np.errstate(over="ignore"):
        key = (bits[:, 0] * np.uint64(0x9E3779B97F4A7C15)) ^ (bits[:, 1] * np.uint64(0xC2B2AE3D27D4EB4F)) ^ bits[:, 2]
    _, first, inverse = np.unique(key, return_index=True, return_inverse=True)
    inverse = inverse.ravel()
    if not np.array_equal(bits, bits[first[inverse]]):
        keys = pts.view(np.dtype((np.void, 24))).ravel()
        _, first, inverse = np.unique(keys, return_index=True, return_inverse=True)
        inverse = inverse.ravel()
    return first, inverse


def _welded_triangles(positions: np.ndarray, welded: tuple[np.ndarray, np.ndarray] | None = None
                      ) -> tuple[np.ndarray, np.ndarray]:
    """(vertices (V, 3) float64, triangles (F, 3) int64): corners welded when bit-identical.
    welded: weld() of these corners when the caller has it already."""
    corners = np.asarray(positions, dtype=np.float64).reshape(-1, 3)
    first, vertex = weld(corners) if welded is None else welded
    return corners[first], vertex.reshape(-1, 3).astype(np.int64)


# surface_holes of the last few sets of triangles, by the bytes of their corners: a re-bake
# plans the scene before an edit (which the bake before it planned too), after it, and its
# cells (the same scene again); the holes took 0.04 s of each plan for 24k triangles.
HOLES_REMEMBERED = 4
_holes_by_corners: OrderedDict[tuple, list[np.ndarray] | None] = OrderedDict()


def surface_holes(positions: np.ndarray, welded: tuple[np.ndarray, np.ndarray] | None = None
                  ) -> list[np.ndarray] | None:
    """_surface_holes (below) of (F, 3, 3) triangles, remembered for the last
    HOLES_REMEMBERED sets of corners (its loops are read-only arrays)."""
    corners = np.ascontiguousarray(positions)
    key = (corners.dtype.str, corners.shape, hashlib.blake2b(corners.view(np.uint8), digest_size=16).digest())
    if key in _holes_by_corners:
        _holes_by_corners.move_to_end(key)
        return _holes_by_corners[key]
    holes = _surface_holes(corners, welded)
    for loop in holes or ():
        loop.setflags(write=False)
    _holes_by_corners[key] = holes
    while len(_holes_by_corners) > HOLES_REMEMBERED:
        _holes_by_corners.popitem(last=False)
    return holes


def _surface_holes(positions: np.ndarray, welded: tuple[np.ndarray, np.ndarray] | None = None
                   ) -> list[np.ndarray] | None:
    """The holes of (F, 3, 3) triangles that bound solids: one (k, 3) float64 array of
    boundary-loop vertices per hole, [] for closed surfaces, None when the triangles do not
    bound solids even after capping their holes.

    Bounding solids means: after welding bit-identical corners, every directed edge a->b occurs
    at most once (no fin, no flipped face), each border vertex starts and ends exactly one
    border edge (the border splits into simple loops), and with every loop capped by a fan to
    its centroid (which closes it: cap (b, a, c) pairs border edge a->b) the signed volume is
    positive (faces point out). Separate objects, touching or intersecting, may each be such.

    Why it matters: a ray from outside first crosses such a capped surface where it enters,
    at a face that looks towards the ray's origin or at a cap. So a depth map from a light
    equals the map of the light-facing faces alone except inside the light-view outline of a
    hole (the cap lies in the convex hull of its loop): faces turned away from the light are
    needed only there (on llvmpipe they cost about 40 % of a light view).
    welded: weld() of the corners, when the caller has it already.
    """
    if len(np.asarray(positions).reshape(-1, 9)) == 0:
        return None
    verts, tri = _welded_triangles(positions, welded)
    a = tri.ravel()
    b = np.roll(tri, -1, axis=1).ravel()
    if (a == b).any():  # a collapsed edge: no consistent orientation to speak of
        return None
    n = len(verts)
    forward = a * n + b
    order = np.sort(forward)
    if (np.diff(order) == 0).any():  # a directed edge used twice: fin or flipped neighbour
        return None
    # Edge a->b is a border edge when no face walks b->a, i.e. a * n + b is not a reversed
    # edge. Both lists sorted: searchsorted with sorted queries runs in cache order.
    reversed_sorted = np.sort(b * n + a)
    slot = np.minimum(np.searchsorted(reversed_sorted, order), len(order) - 1)
    border = order[reversed_sorted[slot] != order]
    start, end = border // n, border % n
    loops = _border_loops(start, end)
    if loops is None:
        return None
    if not _capped_parts_enclose_volume(verts, tri, loops, start, end):
        return None
    return [verts[loop] for loop in loops]


def _capped_parts_enclose_volume(verts: np.ndarray, tri: np.ndarray, loops: list[np.ndarray], start: np.ndarray,
                                 end: np.ndarray) -> bool:
    """Whether every connected part of the welded triangles (verts (V, 3), tri (F, 3)), each
    border loop capped by a fan to its centroid (border edges start -> end), encloses a
    positive volume."""
    n = len(verts)
    # Signed volume of each connected part plus its caps (divergence theorem, corners relative
    # to the mean so large offsets do not cancel digits). Every part must enclose a positive
    # volume: one inside-out part (or a sheet, which capped by itself encloses nothing) among
    # solids would break the argument above where it is, whatever the total.
    p = verts - verts.mean(axis=0)
    part = component_labels(tri, n)
    det = np.einsum("ij,ij->i", p[tri[:, 0]], np.cross(p[tri[:, 1]], p[tri[:, 2]]))
    loop_of = np.empty(n, np.int64)
    centroids = np.zeros((len(loops), 3))
    for i, loop in enumerate(loops):
        loop_of[loop] = i
        centroids[i] = p[loop].mean(axis=0)
    owner = part[tri[:, 0]]
    if len(loops):
        cap_det = np.einsum("ij,ij->i", p[end], np.cross(p[start], centroids[loop_of[start]]))
        det = np.concatenate([det, cap_det])
        owner = np.concatenate([owner, part[start]])
    volume = np.bincount(owner, weights=det, minlength=n)
    size = np.bincount(owner, weights=np.abs(det), minlength=n)
    used = np.unique(owner)
    return bool((volume[used] > 1e-6 * size[used]).all())


def _border_loops(start: np.ndarray, end: np.ndarray) -> list[np.ndarray] | None:
    """The closed loops of border edges start[i] -> end[i] (welded vertex numbers), each as
    its vertices in order; None where a vertex has two loops through it or a walk breaks off."""
    if len(np.unique(start)) != len(start) or len(np.unique(end)) != len(end):
        return None  # a border vertex with two loops through it
    successor = dict(zip(start.tolist(), end.tolist()))
    loops, seen = [], set()
    for first in successor:
        if first in seen:
            continue
        loop, v = [], first
        while v not in seen:
            seen.add(v)
            loop.append(v)
            v = successor.get(v, -1)
            if v < 0:
                return None
        loops.append(np.array(loop))
    return loops


def component_labels(tri: np.ndarray, vertex_count: int) -> np.ndarray:
    """(V,) int64 label of each vertex's connected part (the smallest vertex number in it)
    for (F, 3) int vertex triangles."""
    tri = np.asarray(tri)
    return root_labels(vertex_count, np.concatenate([tri[:, [0, 1]], tri[:, [1, 2]]]))


def is_closed_surface(positions: np.ndarray) -> bool:
    """True when (F, 3, 3) triangles form closed, consistently and outward oriented surfaces:
    every directed edge a->b occurs exactly once and its reverse b->a exactly once after
    welding bit-identical corners (no border, no fin, no flipped face), and the enclosed
    volume is positive. See surface_holes for why it matters."""
    return surface_holes(positions) == []


def boundary_edge_fraction(positions: np.ndarray) -> float:
    """Fraction of the (welded, undirected) edges of (F, 3, 3) triangles that belong to one
    face only: 0 for a closed surface, small for a scan with a few holes, large for sheets."""
    if len(np.asarray(positions).reshape(-1, 9)) == 0:
        return 1.0
    verts, tri = _welded_triangles(positions)
    a, b = tri.ravel(), np.roll(tri, -1, axis=1).ravel()
    n = len(verts)
    _, counts = np.unique(np.minimum(a, b) * n + np.maximum(a, b), return_counts=True)
    return float((counts == 1).sum() / len(counts))


def unit_vectors(v: np.ndarray) -> np.ndarray:
    """(..., 3) vectors scaled to unit length; zero vectors stay zero."""
    length = np.linalg.norm(v, axis=-1, keepdims=True)
    return np.divide(v, length, out=np.zeros_like(v), where=length > 0.0)
