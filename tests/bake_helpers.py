# SPDX-License-Identifier: GPL-3.0-or-later
"""Helpers for bake accuracy tests: texel-centre surface points and sample-count tolerances.

Tolerances. A texel's estimate sums D directions, about D/2 of them in its hemisphere. Were
they independent random directions, the standard error for a binary occlusion pattern would
be at most sigma_D = 0.5 / sqrt(D / 2) (at A = 0.5). The baker's rotated Fibonacci set is a
stratified set, so its error is smaller; the tests allow
    RMSE <= sigma_D / 2,  |bias| <= sigma_D / 8,  max |error| <= 2 sigma_D
over covered texels. A normalization off by 2 % (bias 0.018 on a map averaging 0.9) fails
the bias bound for every D >= 64; a visibility bug fails the RMSE bound.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from hao_addon.core.bake.uv_raster import interior_mask, texel_surface_samples


def sigma(directions: int) -> float:
    return 0.5 / np.sqrt(directions / 2.0)


def texel_points(soup, size: int, rings: int = 1):
    """(points (size, size, 3), interior mask (size, size)) of texel centres on the surface."""
    face, bary, hits = texel_surface_samples(soup.uvs, size)
    pts = np.einsum("yxk,yxkd->yxd", bary, soup.positions[np.maximum(face, 0)])
    return pts, interior_mask(face, hits, rings=rings)


def error_stats(ao: np.ndarray, ref: np.ndarray, mask: np.ndarray) -> dict:
    e = (ao[mask] - ref[mask]).astype(np.float64)
    return dict(rmse=float(np.sqrt((e * e).mean())), bias=float(e.mean()), max=float(np.abs(e).max()),
                p99=float(np.percentile(np.abs(e), 99)), n=int(mask.sum()))


def assert_within_sample_tolerance(stats: dict, directions: int, label: str = "", max_floor: float = 0.0) -> None:
    """max_floor: an error bound that does not shrink with D (the gather's shadow-map
    resolution near contact points); the max-error check uses the larger of the two."""
    s = sigma(directions)
    assert stats["rmse"] <= s / 2, f"{label} RMSE {stats['rmse']:.4f} > {s / 2:.4f} ({stats})"
    assert abs(stats["bias"]) <= s / 8, f"{label} bias {stats['bias']:.4f} > {s / 8:.4f} ({stats})"
    bound = max(2 * s, max_floor)
    assert stats["max"] <= bound, f"{label} max error {stats['max']:.4f} > {bound:.4f} ({stats})"


def load_image_rgba(path) -> np.ndarray:
    """(H, W, 4) float32 pixels of an image file as Blender reads it, Non-Color (row 0 = bottom)."""
    import bpy
    image = bpy.data.images.load(str(path), check_existing=False)
    image.colorspace_settings.name = 'Non-Color'
    w, h = image.size
    px = np.empty(w * h * 4, np.float32)
    image.pixels.foreach_get(px)
    bpy.data.images.remove(image)
    return px.reshape(h, w, 4)


def write_obj(path: Path, objects: dict) -> None:
    """A Wavefront file of named triangle soups (UVs where a soup has them)."""
    lines, base = [], 1
    for name, soup in objects.items():
        lines.append(f"o {name}\n")
        lines += [f"v {x:.9g} {y:.9g} {z:.9g}\n" for x, y, z in soup.positions.reshape(-1, 3)]
        if soup.uvs is not None:
            lines += [f"vt {u:.9g} {v:.9g}\n" for u, v in soup.uvs.reshape(-1, 2)]
        for f in range(soup.face_count):
            idx = [base + 3 * f + k for k in range(3)]
            lines.append("f " + " ".join(f"{i}/{i}" if soup.uvs is not None else str(i) for i in idx) + "\n")
        base += 3 * soup.face_count
    path.write_text("".join(lines))
