# SPDX-License-Identifier: GPL-3.0-or-later
"""The xatlas call, in-process or as a child process (``python unwrap_worker.py IN OUT``).

xatlas holds the interpreter lock for the whole unwrap (seconds for 100k triangles), so in
the calling process no signal handler, progress update or Esc key runs until it returns.
``core/bake/unwrap.py`` therefore runs it here, in a child that can be killed at once. This file
imports only numpy and xatlas: the child must not need the add-on's package to be importable.
"""
from __future__ import annotations

import sys

import numpy as np


def atlas_uvs(vertices: np.ndarray, triangles: np.ndarray, resolution: int, padding: int) -> np.ndarray:
    """Per-corner UVs (F, 3, 2) float64 in [0, 1] of an xatlas atlas packed for `resolution`
    texels with `padding` free texels around each chart. vertices (V, 3) float32 should be
    of unit size near the origin (xatlas' epsilons are absolute); triangles (F, 3) uint32.
    Raises RuntimeError when xatlas does not produce one atlas with every triangle."""
    import xatlas  # shipped as a wheel with the extension

    atlas = xatlas.Atlas()
    atlas.add_mesh(np.ascontiguousarray(vertices, dtype=np.float32), np.ascontiguousarray(triangles, dtype=np.uint32))
    chart_options = xatlas.ChartOptions()
    pack_options = xatlas.PackOptions()
    pack_options.resolution = int(resolution)
    pack_options.padding = int(padding)
    pack_options.bilinear = True
    atlas.generate(chart_options, pack_options)
    if atlas.atlas_count != 1:
        raise RuntimeError(f"xatlas packed {atlas.atlas_count} atlases instead of one")
    _vmapping, indices, uvs = atlas[0]
    if len(indices) != len(triangles):
        raise RuntimeError(f"xatlas returned {len(indices)} triangles for {len(triangles)}")
    return np.asarray(uvs, dtype=np.float64)[np.asarray(indices)]


def main(argv: list[str]) -> int:
    """IN: an .npz with vertices, triangles, resolution, padding. OUT: .npy of the UVs.
    A failure is one line on stderr and exit 1."""
    source, target = argv
    try:
        with np.load(source) as data:
            uvs = atlas_uvs(data["vertices"], data["triangles"], int(data["resolution"]), int(data["padding"]))
        with open(target, "wb") as fh:
            np.save(fh, uvs)
    except Exception as exc:  # reported by the parent as one line
        print(f"{type(exc).__name__}: {exc}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
