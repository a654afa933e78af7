# SPDX-License-Identifier: GPL-3.0-or-later
"""UV layouts that bake, but not as the user probably expects: islands that overlap (their
texels receive the average of several surface points) and UVs outside the 0..1 tile (those
parts are not baked), and triangles of zero UV area (their faces get no texels). Each is
reported as a warning, as Cycles users would want to know."""
from __future__ import annotations

import hashlib
from collections import OrderedDict

import numpy as np

from ..geometry import TriangleSoup
from .udim import UdimLayout

# Overlaps are counted at texel centres of a map at most this large (cost ~ UV area x side^2).
CHECK_SIDE = 512
# Fractions below these are rounding at shared edges, not a layout problem.
OVERLAP_WARN_FRACTION = 1e-3
# UV triangles of zero area (collapsed to a line or a point) get no texel: warned about above
# this share of the triangles (a few slivers are common in real meshes, most is a broken map).
ZERO_AREA_WARN_FRACTION = 0.01
# A UV triangle whose doubled area is below this is taken as zero (float32 UVs of a 1-unit
# tile resolve about 6e-8; a texel of the largest map, 16384^2, is 3.7e-9 of the tile).
ZERO_UV_AREA = 1e-12
CHUNK_CANDIDATES = 1 << 21


def texel_centre_hits(uvs: np.ndarray, side: int) -> np.ndarray:
    """(side, side) int32: how many UV triangles strictly contain each texel centre.

    uvs: (F, 3, 2). Vectorized: every texel centre of each face's box is tested once, in
    chunks of faces whose boxes hold about CHUNK_CANDIDATES centres (bounded memory)."""
    p = np.asarray(uvs, np.float64) * side - 0.5
    lo = np.clip(np.ceil(p.min(axis=1)), 0, side - 1).astype(np.int64)
    hi = np.clip(np.floor(p.max(axis=1)), 0, side - 1).astype(np.int64)
    w = np.maximum(hi[:, 0] - lo[:, 0] + 1, 0)
    h = np.maximum(hi[:, 1] - lo[:, 1] + 1, 0)
    ends = np.cumsum(w * h)
    hits = np.zeros(side * side, np.int32)
    cuts = np.searchsorted(ends, np.arange(CHUNK_CANDIDATES, int(ends[-1]) if len(ends) else 0, CHUNK_CANDIDATES))
    for faces in np.split(np.arange(len(p)), np.unique(cuts)):
        if len(faces):
            _count_chunk(p[faces], lo[faces], w[faces], h[faces], side, hits)
    return hits.reshape(side, side)


def _count_chunk(p, lo, w, h, side, hits) -> None:
    counts = w * h
    total = int(counts.sum())
    if total == 0:
        return
    face = np.repeat(np.arange(len(p)), counts)
    local = np.arange(total) - np.repeat(np.cumsum(counts) - counts, counts)
    xs = lo[face, 0] + local % w[face]
    ys = lo[face, 1] + local // w[face]
    a, b, c = p[face, 0], p[face, 1], p[face, 2]
    det = (b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (c[:, 0] - a[:, 0]) * (b[:, 1] - a[:, 1])
    with np.errstate(divide="ignore", invalid="ignore"):
        w1 = ((xs - a[:, 0]) * (c[:, 1] - a[:, 1]) - (c[:, 0] - a[:, 0]) * (ys - a[:, 1])) / det
        w2 = ((b[:, 0] - a[:, 0]) * (ys - a[:, 1]) - (xs - a[:, 0]) * (b[:, 1] - a[:, 1])) / det
    eps = 1e-7
    inside = (np.abs(det) > 1e-12) & (w1 > eps) & (w2 > eps) & (1.0 - w1 - w2 > eps)
    hits += np.bincount(ys[inside] * side + xs[inside], minlength=side * side).astype(np.int32)


def uv_layout_warnings(uvs: np.ndarray, size: int, name: str) -> tuple[list[str], dict]:
    """Warnings (sentences) and counters for a bake target's UV layout. uvs: (F, 3, 2).

    The numbers are cached by the UVs' content (a re-bake with other settings, or of the same
    map, skips the raster: counter ``uv_check_cached``)."""
    counts = _layout_counts(np.ascontiguousarray(uvs, np.float64), int(size))
    outside, fraction = counts["uv_triangles_outside_tile"], counts["uv_overlap_fraction"]
    warnings = []
    if outside:
        warnings.append(f"'{name}': {outside} of {len(uvs)} UV triangles reach outside the 0..1 UV "
                        f"tile; those parts are not baked")
    zero = counts["uv_triangles_zero_area"]
    if zero > ZERO_AREA_WARN_FRACTION * len(uvs):
        warnings.append(f"'{name}': {zero} of {len(uvs)} UV triangles have zero area in the UV map; those "
                        f"faces get no texels: unwrap them")
    if fraction > OVERLAP_WARN_FRACTION:
        warnings.append(f"'{name}': UV islands overlap on {fraction * 100:.1f} % of the baked texels; "
                        f"those texels get the average of the overlapping surfaces")
    return warnings, counts


_CACHE: "OrderedDict[tuple, dict]" = OrderedDict()
_CACHE_SIZE = 16


def _layout_counts(uvs: np.ndarray, size: int) -> dict:
    key = (hashlib.blake2b(uvs.tobytes(), digest_size=16).digest(), uvs.shape, size)
    if key in _CACHE:
        _CACHE.move_to_end(key)
        return {**_CACHE[key], "uv_check_cached": True}
    # Less than half a texel past the tile's edge, no texel centre is missed.
    tolerance = 0.5 / size
    outside = ((uvs < -tolerance) | (uvs > 1.0 + tolerance)).any(axis=(1, 2))
    hits = texel_centre_hits(uvs, min(size, CHECK_SIDE))
    covered = int((hits > 0).sum())
    edges = uvs[:, 1:] - uvs[:, :1]
    doubled_area = np.abs(edges[:, 0, 0] * edges[:, 1, 1] - edges[:, 0, 1] * edges[:, 1, 0])
    counts = dict(uv_triangles_outside_tile=int(outside.sum()),
                  uv_triangles_zero_area=int((doubled_area < ZERO_UV_AREA).sum()),
                  uv_overlap_fraction=int((hits > 1).sum()) / covered if covered else 0.0)
    _CACHE[key] = counts
    while len(_CACHE) > _CACHE_SIZE:
        _CACHE.popitem(last=False)
    return {**counts, "uv_check_cached": False}


def tile_layout_warnings(target: TriangleSoup, size: int, udim: UdimLayout | None) -> tuple[list[str], dict]:
    """uv_layout_warnings of the 0..1 tile, or of each UDIM tile (its triangles moved into
    0..1; counters summed, the overlap fraction the largest)."""
    if udim is None:
        return uv_layout_warnings(target.uvs, size, target.name)
    warnings, counters = [], {}
    for tile, number in enumerate(udim.tiles):
        _faces, local = udim.local_uvs(target.uvs, tile)
        tile_warnings, tile_counters = uv_layout_warnings(local, size, f"{target.name}' tile '{number}")
        warnings += tile_warnings
        for key, value in tile_counters.items():
            if isinstance(value, bool):
                counters[key] = counters.get(key, True) and value
            elif key.endswith("fraction"):
                counters[key] = max(counters.get(key, 0.0), value)
            else:
                counters[key] = counters.get(key, 0) + value
    return warnings, counters
