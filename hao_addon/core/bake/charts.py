# SPDX-License-Identifier: GPL-3.0-or-later
"""UV charts of a mesh without UVs, from planar projections (numpy only; no bpy, no xatlas).

The segmentation Blender's Smart UV Project makes, in array operations: projection
directions chosen from the face normals (each direction the area-weighted mean of the faces
within the angle limit of the largest face not yet covered, refined by a few k-means steps),
every face on the direction nearest its normal, islands = edge-connected faces of one
direction, islands smaller than SMALL_ISLAND faces absorbed by a neighbour whose direction
still sees them, and each island projected flat on its direction's plane. xatlas only packs
these charts (``unwrap_worker.py``); its own chart growing took 17 s on the 69k-triangle
bunny, this takes under a second.

A projected island can still overlap itself where the surface winds over itself while
facing one way (a spiral ramp). ``overlapping_faces`` finds that on the packed atlas and
``split_islands`` cuts such islands in two at their median height along the projection
direction, until nothing overlaps (at the last resort every such face is its own chart).

Charts are made of whole polygons: given each triangle's polygon (a quad's two triangles, an
n-gon's fan), every step (direction, absorption, splits) decides per polygon, so the
corners a polygon's triangles share get one UV. Blender stores UVs per polygon corner: a
quad split across two charts would write one of them over the other (Suzanne without UVs
overlapped on half its texels that way).

This file imports only numpy and ``core/components.py``: the unwrap's child process loads
it by file name.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

try:
    from ..components import connected_components
except ImportError:  # the unwrap's child process: unwrap_worker.py puts core/ on sys.path
    from components import connected_components

# Smart UV Project's default angle limit: a face joins the direction within this angle.
ANGLE_LIMIT_DEG = 66.0
# Islands below this many faces are absorbed by a neighbouring island...
SMALL_ISLAND = 16
# ...whose direction is within acos(0.34) = 70 degrees of the face's normal (a flatter
# projection would squash it more than 3x).
ABSORB_MIN_COS = 0.34
ABSORB_ROUNDS = 6
REFINE_STEPS = 4
MAX_DIRECTIONS = 64


@dataclass
class Charts:
    """A mesh cut into flat charts. uvs: (F, 3, 2) float64 planar coordinates in the unit
    copy's units (charts overlap each other until packed); island: (F,) chart of each face;
    direction: (K, 3) projection directions; face_direction: (F,) index into direction;
    uv_vertex: (F, 3) int index of each corner's UV vertex (corners of one vertex in one
    chart share it, so a packer sees the charts as connected pieces)."""

    uvs: np.ndarray
    island: np.ndarray
    direction: np.ndarray
    face_direction: np.ndarray
    uv_vertex: np.ndarray

    @property
    def count(self) -> int:
        return int(self.island.max()) + 1 if len(self.island) else 0

    def welded_uvs(self) -> np.ndarray:
        """(U, 2) float32: the UV of each uv_vertex."""
        out = np.zeros((int(self.uv_vertex.max()) + 1, 2), np.float32)
        out[self.uv_vertex.ravel()] = self.uvs.reshape(-1, 2)
        return out


def normals_and_areas(corners: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """corners (F, 3, 3) -> unit normals (F, 3) (zero for degenerate faces), areas (F,)."""
    cross = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    length = np.linalg.norm(cross, axis=1)
    return cross / np.maximum(length, 1e-300)[:, None], 0.5 * length


def projection_directions(normals: np.ndarray, areas: np.ndarray, angle_limit_deg: float = ANGLE_LIMIT_DEG
                          ) -> np.ndarray:
    """(K, 3) unit directions such that every face normal is within the angle limit of one
    (greedy cover from the largest uncovered face), refined by k-means on the normals."""
    cos_limit = np.cos(np.radians(angle_limit_deg))
    usable = areas > 0
    best = np.where(usable, -2.0, 2.0)
    chosen: list[np.ndarray] = []
    while len(chosen) < MAX_DIRECTIONS:
        uncovered = best < cos_limit
        if not uncovered.any():
            break
        seed = np.flatnonzero(uncovered)[np.argmax(areas[uncovered])]
        near = uncovered & (normals @ normals[seed] > cos_limit)
        mean = (normals[near] * areas[near, None]).sum(axis=0)
        direction = mean / np.linalg.norm(mean) if np.linalg.norm(mean) > 0 else normals[seed]
        chosen.append(direction)
        best = np.maximum(best, normals @ direction)
    directions = np.array(chosen) if chosen else np.array([[0.0, 0.0, 1.0]])
    for _ in range(REFINE_STEPS):
        label = np.argmax(normals @ directions.T, axis=1)
        sums = np.zeros_like(directions)
        np.add.at(sums, label, normals * areas[:, None])
        length = np.linalg.norm(sums, axis=1)
        directions = np.where(length[:, None] > 0, sums / np.maximum(length, 1e-300)[:, None], directions)
    return directions


def adjacent_faces(triangles: np.ndarray) -> np.ndarray:
    """(P, 2) pairs of faces that share an edge (vertex indices, so weld first); an edge of
    n > 2 faces links them in a chain."""
    edges = np.sort(np.concatenate([triangles[:, [0, 1]], triangles[:, [1, 2]], triangles[:, [2, 0]]]), axis=1)
    faces = np.tile(np.arange(len(triangles)), 3)
    key = edges[:, 0].astype(np.int64) * (int(triangles.max()) + 1) + edges[:, 1]
    order = np.argsort(key, kind="stable")
    key, faces = key[order], faces[order]
    same = key[1:] == key[:-1]
    pairs = np.stack([faces[:-1][same], faces[1:][same]], axis=1)
    return pairs[pairs[:, 0] != pairs[:, 1]]


def islands_of(face_direction: np.ndarray, pairs: np.ndarray) -> np.ndarray:
    """Edge-connected faces of one direction form an island: (F,) island index."""
    keep = face_direction[pairs[:, 0]] == face_direction[pairs[:, 1]]
    return connected_components(len(face_direction), pairs[keep])


def absorb_small_islands(normals: np.ndarray, face_direction: np.ndarray, pairs: np.ndarray,
                         directions: np.ndarray) -> np.ndarray:
    """face_direction with the faces of islands under SMALL_ISLAND faces moved to the
    direction of their largest neighbouring island, where that direction still sees them
    (cos >= ABSORB_MIN_COS). Fewer, larger charts pack tighter and cut fewer seams."""
    label = face_direction.copy()
    both = np.concatenate([pairs, pairs[:, ::-1]])  # (face, neighbour)
    for _ in range(ABSORB_ROUNDS):
        island = islands_of(label, pairs)
        size = np.bincount(island)[island]
        face, other = both[:, 0], both[:, 1]
        ok = (size[face] < SMALL_ISLAND) & (label[other] != label[face]) & (size[other] > size[face])
        face, other = face[ok], other[ok]
        ok = np.einsum("ij,ij->i", normals[face], directions[label[other]]) >= ABSORB_MIN_COS
        face, other = face[ok], other[ok]
        if not len(face):
            break
        order = np.lexsort((-size[other], face))  # per face, its largest neighbouring island first
        face, other = face[order], other[order]
        first = np.r_[True, face[1:] != face[:-1]]
        label[face[first]] = label[other[first]]
    return label


def plane_bases(directions: np.ndarray) -> np.ndarray:
    """(K, 2, 3): two unit vectors spanning the plane normal to each direction."""
    helper = np.where(np.abs(directions[:, :1]) < 0.9, [[1.0, 0.0, 0.0]], [[0.0, 1.0, 0.0]])
    e1 = np.cross(directions, helper)
    e1 /= np.linalg.norm(e1, axis=1, keepdims=True)
    e2 = np.cross(directions, e1)
    return np.stack([e1, e2], axis=1)


def _charts(corners: np.ndarray, triangles: np.ndarray, directions: np.ndarray, face_direction: np.ndarray,
            island: np.ndarray) -> Charts:
    uvs = np.einsum("fcj,fkj->fck", corners, plane_bases(directions)[face_direction])
    uvs = _side_by_side(uvs, island)
    key = triangles.astype(np.int64) * (int(island.max()) + 1) + island[:, None]
    uv_vertex = np.unique(key.ravel(), return_inverse=True)[1].reshape(-1, 3)
    return Charts(uvs, island, directions, face_direction, uv_vertex)


def _side_by_side(uvs: np.ndarray, island: np.ndarray) -> np.ndarray:
    """The islands moved apart along u (each starting one unit past the last one's end):
    xatlas joins faces whose UVs touch into one chart, so islands projected onto the same
    spot (a cube's opposite faces) would be packed as one."""
    count = int(island.max()) + 1
    low = np.full((count, 2), np.inf)
    high = np.full((count, 2), -np.inf)
    np.minimum.at(low, island, uvs.min(axis=1))
    np.maximum.at(high, island, uvs.max(axis=1))
    width = np.nan_to_num(high[:, 0] - low[:, 0]) + 1.0
    start = np.concatenate([[0.0], np.cumsum(width)[:-1]])
    return uvs - low[island][:, None] + np.stack([start, np.zeros(count)], axis=1)[island][:, None]


def welded_corners(vertices: np.ndarray, triangles: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(F, 3, 3) float64 corner positions and (F, 3) triangles re-indexed so that vertices at
    one position are one vertex (a mesh of separate triangles still has neighbours)."""
    vertices, triangles = np.asarray(vertices), np.asarray(triangles, np.int64)
    _unique, index = np.unique(vertices, axis=0, return_inverse=True)
    return vertices[triangles].astype(np.float64), index.reshape(-1)[triangles]


def polygon_leaders(polygons: np.ndarray | None, count: int) -> np.ndarray:
    """(F,) for each triangle the first triangle of its polygon (polygons: (F,) polygon
    index of each triangle, or None: every triangle is its own polygon). A per-triangle
    label indexed by this is one label per polygon."""
    if polygons is None:
        return np.arange(count)
    polygons = np.asarray(polygons, np.int64)
    _unique, first, inverse = np.unique(polygons, return_index=True, return_inverse=True)
    return first[inverse.reshape(-1)]


def polygon_pairs(leader: np.ndarray) -> np.ndarray:
    """(P, 2) each triangle paired with its polygon's first (polygon_leaders): what joins a
    polygon's triangles in one chart even where they share no welded edge (Blender writes a
    UV per loop, so a polygon split across charts gets one chart's UVs at its shared corners:
    two of Suzanne's quads were, and their written triangles overlapped 1.2 % of the map)."""
    faces = np.flatnonzero(leader != np.arange(len(leader)))
    return np.stack([faces, leader[faces]], axis=1)


def polygon_normals(normals: np.ndarray, areas: np.ndarray, leader: np.ndarray) -> np.ndarray:
    """(F, 3): each triangle's polygon's area-weighted unit normal (a non-planar quad's two
    triangles see one normal, so they choose one direction)."""
    sums = np.zeros_like(normals)
    np.add.at(sums, leader, normals * areas[:, None])
    length = np.linalg.norm(sums, axis=1)
    unit = np.where(length[:, None] > 0, sums / np.maximum(length, 1e-300)[:, None], normals)
    return unit[leader]


def projection_charts(vertices: np.ndarray, triangles: np.ndarray, angle_limit_deg: float = ANGLE_LIMIT_DEG,
                      polygons: np.ndarray | None = None) -> Charts:
    """Planar charts of the mesh: vertices (V, 3) of about unit size, triangles (F, 3),
    polygons (F,) each triangle's polygon (None: triangles are the polygons)."""
    corners, triangles = welded_corners(vertices, triangles)
    normals, areas = normals_and_areas(corners)
    leader = polygon_leaders(polygons, len(triangles))
    normals = polygon_normals(normals, areas, leader)
    directions = projection_directions(normals, areas, angle_limit_deg)
    pairs = adjacent_faces(triangles)
    face_direction = absorb_small_islands(normals, np.argmax(normals @ directions.T, axis=1), pairs, directions)
    face_direction = face_direction[leader]  # absorption looked at neighbours per triangle
    pairs = np.concatenate([pairs, polygon_pairs(leader)])
    return _charts(corners, triangles, directions, face_direction, islands_of(face_direction, pairs))


def split_islands(charts: Charts, vertices: np.ndarray, triangles: np.ndarray, which: np.ndarray,
                  alone: bool = False, polygons: np.ndarray | None = None) -> Charts:
    """The charts with each island in `which` cut in two at its median height along its
    direction (then split into edge-connected pieces); alone: its polygons become one chart
    each instead. A polygon's triangles stay together (polygons as projection_charts')."""
    corners, triangles = welded_corners(vertices, triangles)
    island = charts.island.copy()
    leader = polygon_leaders(polygons, len(island))
    chosen = np.isin(island, which)
    if alone:
        part = np.where(chosen, leader, -1)
    else:
        height = np.einsum("fj,fj->f", corners.mean(axis=1), charts.direction[charts.face_direction])
        sums = np.zeros(len(island))
        np.add.at(sums, leader, height)
        height = sums[leader] / np.bincount(leader, minlength=len(island))[leader]  # the polygon's mean
        median = np.zeros(charts.count)
        for i in np.unique(island[chosen]):
            median[i] = np.median(height[island == i])
        part = np.where(chosen, (height > median[island]).astype(np.int64), -1)
    label = island * (len(island) + 1) + part + 1  # unchosen islands keep one label
    pairs = np.concatenate([adjacent_faces(triangles), polygon_pairs(leader)])
    keep = label[pairs[:, 0]] == label[pairs[:, 1]]
    new_island = connected_components(len(island), pairs[keep])
    direction, face_direction = charts.direction, charts.face_direction
    if alone and chosen.any():  # each polygon along its own normal: a bent quad seen askew folds over itself
        normals, areas = normals_and_areas(corners)
        own = polygon_normals(normals, areas, leader)[chosen]
        face_direction = face_direction.copy()
        face_direction[chosen] = len(direction) + np.arange(int(chosen.sum()))
        direction = np.concatenate([direction, own])
    return _charts(corners, triangles, direction, face_direction, new_island)


def overlapping_faces(uvs: np.ndarray, size: int) -> np.ndarray:
    """Indices of the faces whose UV triangles (F, 3, 2) in [0, 1] share a texel centre of
    a size x size grid with another face (strictly inside both: shared edges do not count)."""
    pixel, face = texel_hits(uvs, size)
    twice = np.bincount(pixel, minlength=size * size)[pixel] > 1
    return np.unique(face[twice])


def overlapping_texels(uvs: np.ndarray, size: int) -> tuple[int, int]:
    """(texel centres strictly inside two or more UV triangles, texel centres covered) of a
    size x size grid: the overlap a bake into these UVs would write twice."""
    pixel, _face = texel_hits(uvs, size)
    counts = np.bincount(pixel, minlength=size * size)
    return int((counts > 1).sum()), int((counts > 0).sum())


def texel_hits(uvs: np.ndarray, size: int) -> tuple[np.ndarray, np.ndarray]:
    """(pixel, face): one entry per texel centre strictly inside a UV triangle (F, 3, 2) of
    a size x size grid (pixel = y * size + x); vectorized by the triangles' texel span."""
    p = np.asarray(uvs, np.float64) * size - 0.5  # texel-centre coordinates
    lo = np.floor(p.min(axis=1)).astype(np.int64) + 1
    hi = np.floor(p.max(axis=1)).astype(np.int64)
    span = np.maximum(hi - lo + 1, 0)
    pixel_parts, face_parts = [np.zeros(0, np.int64)], [np.zeros(0, np.int64)]
    for side in np.unique(np.maximum(span[:, 0], span[:, 1])):
        if side == 0:
            continue
        faces = np.flatnonzero(np.maximum(span[:, 0], span[:, 1]) == side)
        for start in range(0, len(faces), max(1, 2**22 // (side * side))):
            f = faces[start:start + max(1, 2**22 // (side * side))]
            dy, dx = np.mgrid[0:side, 0:side]
            xs = lo[f, 0, None] + dx.ravel()[None]
            ys = lo[f, 1, None] + dy.ravel()[None]
            a, b, c = p[f, 0, :, None], p[f, 1, :, None], p[f, 2, :, None]
            det = (b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (c[:, 0] - a[:, 0]) * (b[:, 1] - a[:, 1])
            safe = np.where(np.abs(det) > 1e-12, det, 1.0)
            w1 = ((xs - a[:, 0]) * (c[:, 1] - a[:, 1]) - (c[:, 0] - a[:, 0]) * (ys - a[:, 1])) / safe
            w2 = ((b[:, 0] - a[:, 0]) * (ys - a[:, 1]) - (xs - a[:, 0]) * (b[:, 1] - a[:, 1])) / safe
            inside = (w1 > 1e-7) & (w2 > 1e-7) & (1.0 - w1 - w2 > 1e-7) & (np.abs(det) > 1e-12)
            inside &= (xs >= 0) & (xs < size) & (ys >= 0) & (ys < size)
            pixel_parts.append((ys * size + xs)[inside])
            face_parts.append(np.broadcast_to(f[:, None], inside.shape)[inside])
    return np.concatenate(pixel_parts), np.concatenate(face_parts)
