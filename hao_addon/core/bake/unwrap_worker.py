# SPDX-License-Identifier: GPL-3.0-or-later
"""The unwrap, in-process or as a child process (``python unwrap_worker.py IN OUT``).

Charts come from planar projections (``charts.py``, numpy); xatlas packs them. xatlas holds
the interpreter lock while it runs, so ``core/bake/unwrap.py`` runs this in a child that can
be killed at once. This file imports only numpy, xatlas, its sibling ``charts.py`` and ``core/components.py`` (by
file name in the child): the child must not need the add-on's package to be importable.
"""
from __future__ import annotations

import sys

import numpy as np

try:
    from .charts import Charts, overlapping_faces, projection_charts, split_islands
except ImportError:  # the child process: run as a script beside charts.py, below components.py
    from pathlib import Path
    sys.path.insert(1, str(Path(__file__).resolve().parent.parent))
    from charts import Charts, overlapping_faces, projection_charts, split_islands

# The packed atlas is checked for overlaps at the texel centres of the texture it is packed
# for (what a bake samples; twice the resolution cost the bunny's 1024^2 atlas 1.2 s, once
# 0.3 s); a chart that overlaps itself is cut in two, at most SPLIT_ROUNDS times, the last
# time into single faces.
CHECK_SCALE = 1
SPLIT_ROUNDS = 8


# xatlas, given a resolution, either packs an atlas of its own size (478^2 texels for the
# bunny at 256) that the UVs then squeeze into the texture, padding and all, or, at a fixed
# scale, spills charts into a second atlas. So the charts are packed into one atlas at an
# explicit scale (texels per unit): first the scale that would fill FIRST_FILL of the
# texture, then shrunk by the ratio of the atlas' side to the texture's until it fits
# (2-4 packs: the padding does not shrink with the charts).
FIRST_FILL = 0.6
SHRINK_MARGIN = 0.995
MAX_PACKS = 12


def pack_charts(charts: Charts, resolution: int, padding: int) -> np.ndarray:
    """(F, 3, 2) float64 UVs in [0, 1]: the charts packed by xatlas into one atlas of at most
    `resolution` x `resolution` texels with `padding` free texels of the texture around
    each chart (bilinear-safe). Raises RuntimeError when xatlas cannot pack the triangles."""
    import xatlas  # shipped as a wheel with the extension

    uv_vertices = charts.welded_uvs()
    indices = np.ascontiguousarray(charts.uv_vertex, dtype=np.uint32)
    e1, e2 = charts.uvs[:, 1] - charts.uvs[:, 0], charts.uvs[:, 2] - charts.uvs[:, 0]
    area = float(np.abs(e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0]).sum()) / 2
    texels_per_unit = float(np.sqrt(FIRST_FILL * resolution ** 2 / max(area, 1e-30)))
    for _attempt in range(MAX_PACKS):
        atlas = xatlas.Atlas()
        atlas.add_uv_mesh(uv_vertices, indices)
        pack_options = xatlas.PackOptions()
        pack_options.padding = int(padding)
        pack_options.bilinear = True
        pack_options.texels_per_unit = texels_per_unit
        atlas.generate(xatlas.ChartOptions(), pack_options)
        side = max(atlas.width, atlas.height)
        if atlas.atlas_count == 1 and side <= resolution:
            break
        texels_per_unit *= min(resolution / max(side, 1), 1.0) * SHRINK_MARGIN
    else:
        raise RuntimeError(f"xatlas could not pack the {charts.count} charts into {resolution}^2 texels")
    _vmapping, out_indices, uvs = atlas[0]
    if len(out_indices) != len(indices):
        raise RuntimeError(f"xatlas returned {len(out_indices)} triangles for {len(indices)}")
    # xatlas' UVs span its atlas; the texture is `resolution` texels wide.
    packed = (np.asarray(uvs, dtype=np.float64) * [atlas.width / resolution, atlas.height / resolution])
    return placed_charts(charts, packed[np.asarray(out_indices)])


# A corner whose packed position is off its chart's transform by more than this many times
# the median offset (and more than a millionth of the texture) is one xatlas misplaced.
OUTLIER_FACTOR = 20.0


def placed_charts(charts: Charts, packed: np.ndarray) -> np.ndarray:
    """(F, 3, 2): each chart's planar UVs moved by the one similarity (rotation, mirror,
    scale, offset) that xatlas gave it, fitted to the packed corners (F, 3, 2). xatlas
    keeps a chart rigid but can misplace a single vertex (one shared by 640 triangles at a
    UV sphere's pole landed at the atlas' corner); the fit, without such outliers, puts every
    corner where its chart went."""
    out = np.empty_like(packed)
    planar = charts.uvs
    for chart in range(charts.count):
        faces = np.flatnonzero(charts.island == chart)
        source = planar[faces].reshape(-1, 2)
        target = packed[faces].reshape(-1, 2)
        keep = np.ones(len(source), bool)
        for _round in range(3):
            design = np.column_stack([source[keep], np.ones(int(keep.sum()))])
            transform, *_ = np.linalg.lstsq(design, target[keep], rcond=None)  # (3, 2): [A; t]
            residual = np.linalg.norm(np.column_stack([source, np.ones(len(source))]) @ transform - target, axis=1)
            limit = max(OUTLIER_FACTOR * float(np.median(residual)), 1e-6)
            if np.array_equal(residual <= limit, keep):
                break
            keep = residual <= limit
        out[faces] = (np.column_stack([source, np.ones(len(source))]) @ transform).reshape(-1, 3, 2)
    return out


def atlas_uvs(vertices: np.ndarray, triangles: np.ndarray, resolution: int, padding: int,
              polygons: np.ndarray | None = None) -> np.ndarray:
    """Per-corner UVs (F, 3, 2) float64 in [0, 1] of an atlas of planar charts packed for
    `resolution` texels with `padding` free texels around each chart, no two faces sharing
    a point. vertices (V, 3) float32 should be of unit size near the origin (xatlas' epsilons
    are absolute); triangles (F, 3) uint32; polygons (F,) each triangle's polygon (its
    triangles stay in one chart) or None. Raises RuntimeError when packing fails."""
    charts = projection_charts(vertices, triangles, polygons=polygons)
    for round_ in range(SPLIT_ROUNDS + 1):
        uvs = pack_charts(charts, resolution, padding)
        overlapping = overlapping_faces(uvs, CHECK_SCALE * int(resolution))
        if not len(overlapping):
            return uvs
        if round_ == SPLIT_ROUNDS:
            break
        charts = split_islands(charts, vertices, triangles, np.unique(charts.island[overlapping]),
                               alone=round_ == SPLIT_ROUNDS - 1, polygons=polygons)
    raise RuntimeError(f"{len(overlapping)} faces still overlap after {SPLIT_ROUNDS} splits")


def xatlas_uvs(vertices: np.ndarray, triangles: np.ndarray, resolution: int, padding: int) -> np.ndarray:
    """Per-corner UVs (F, 3, 2) float64 in [0, 1] of xatlas' own charts (its segmentation and
    parametrization of the 3D mesh, slower than atlas_uvs' planar charts: the bunny's 69k
    triangles took 14.6 s against 0.7 s) packed for `resolution` texels with `padding`: the
    fallback where the planar charts overlap as a bake reads them. Raises RuntimeError when
    xatlas' atlas is not one, or its faces overlap at texel centres."""
    import xatlas  # shipped as a wheel with the extension

    atlas = xatlas.Atlas()
    atlas.add_mesh(np.ascontiguousarray(vertices, np.float32), np.ascontiguousarray(triangles, np.uint32))
    pack_options = xatlas.PackOptions()
    pack_options.padding, pack_options.bilinear, pack_options.resolution = int(padding), True, int(resolution)
    atlas.generate(xatlas.ChartOptions(), pack_options)
    if atlas.atlas_count != 1:
        raise RuntimeError(f"xatlas made {atlas.atlas_count} atlases, not one")
    vmapping, indices, uvs = atlas[0]
    if len(indices) != len(triangles):
        raise RuntimeError(f"xatlas returned {len(indices)} triangles for {len(triangles)}")
    out = np.asarray(uvs, np.float64)[np.asarray(indices)]
    overlapping = overlapping_faces(out, CHECK_SCALE * int(resolution))
    if len(overlapping):
        raise RuntimeError(f"{len(overlapping)} faces of xatlas' own atlas overlap")
    return out


UNWRAPS = {"charts": atlas_uvs, "xatlas": lambda v, t, r, p, _polygons: xatlas_uvs(v, t, r, p)}


def main(argv: list[str]) -> int:
    """IN: an .npz with vertices, triangles, resolution, padding (and the way: UNWRAPS' key,
    'charts' where absent). OUT: .npy of the UVs. A failure is one line on stderr and exit 1."""
    source, target = argv
    try:
        with np.load(source) as data:
            polygons = data["polygons"] if "polygons" in data.files else None
            way = str(data["way"]) if "way" in data.files else "charts"
            uvs = UNWRAPS[way](data["vertices"], data["triangles"], int(data["resolution"]), int(data["padding"]),
                               polygons)
        with open(target, "wb") as fh:
            np.save(fh, uvs)
    except Exception as exc:  # reported by the parent as one line
        print(f"{type(exc).__name__}: {exc}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
