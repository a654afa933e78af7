# SPDX-License-Identifier: GPL-3.0-or-later
"""glTF's occlusion-roughness-metallic texture (pure numpy): R the baked AO, G roughness, B
metallic, each per texel of the baked UV layout, sampled from the surface's materials."""
from __future__ import annotations

import numpy as np

from .seams import dilate
from .uv_raster import texel_surface_samples


def sample_nearest(image: np.ndarray, uv: np.ndarray) -> np.ndarray:
    """(m, C) texels of image (H, W, C), row 0 at v = 0, at uv (m, 2), nearest and repeating."""
    h, w = image.shape[:2]
    col = np.clip(np.floor(np.mod(uv[:, 0], 1.0) * w).astype(np.int64), 0, w - 1)
    row = np.clip(np.floor(np.mod(uv[:, 1], 1.0) * h).astype(np.int64), 0, h - 1)
    return image[row, col]


def channel_map(uvs: np.ndarray, size: int, face_value, margin: int) -> np.ndarray:
    """(size, size) float32 of a surface channel in a UV layout uvs (F, 3, 2): at each texel
    centre, face_value(face (m,), bary (m, 3)) -> (m,) of the triangle holding it; grown past
    the islands by margin texels (as the AO map is), and beyond that the channel's mean over
    the islands: a defined, neutral value that a mipmap's coarse levels blend in (0 there made
    an ORM texture pure red outside its islands: roughness 0, a mirror)."""
    face, bary, hits = texel_surface_samples(uvs, size)
    covered = face >= 0
    values = np.zeros((size, size), np.float32)
    values[covered] = face_value(face[covered], bary[covered])
    grown, filled = dilate(values, covered, margin + 2)
    background = float(values[covered].mean()) if covered.any() else 0.0
    return np.where(filled, grown, background).astype(np.float32)


def orm_image(ao: np.ndarray, roughness: np.ndarray, metallic: np.ndarray) -> np.ndarray:
    """(H, W, 4) RGBA: R = ao, G = roughness, B = metallic (each (H, W) in [0, 1]), A = 1."""
    return np.stack([ao, roughness, metallic, np.ones_like(ao)], axis=-1).astype(np.float32)
