# SPDX-License-Identifier: GPL-3.0-or-later
"""Alpha-aware occluders (pure numpy): a material's alpha lets light through an occluder.

A soup's alpha (SoupAlpha) is a constant per face times, where the material has one, an
alpha image on the soup's own UVs. The bake draws what a plan gathers here (DrawnAlpha, one
row per drawn face, the images stacked as layers of one array texture) and, per light view,
keeps each occluder fragment with probability alpha ('blend': over the directions the
expected visibility through surfaces of alphas a_i is prod(1 - a_i)), or where alpha reaches
the clip threshold ('clip'). The reference traces every surface along a ray and weighs them
the same way (expected_visibility), so both are the same estimator.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

# Alpha images are resampled (nearest) to one square side for the array texture: at most this.
MAX_ALPHA_SIDE = 2048


@dataclass
class SoupAlpha:
    """constant: (F,) float32 in [0, 1] per face; images: (H, W) float32 alphas in [0, 1],
    row 0 at v = 0 (Blender's pixel order), face k sampling images[image_index[k]] (-1: none)
    at its uvs (F, 3, 2); None where no face has an image."""

    constant: np.ndarray
    images: list[np.ndarray] = field(default_factory=list)
    image_index: np.ndarray | None = None
    uvs: np.ndarray | None = None
    notes: tuple[str, ...] = ()  # what was read as opaque and why (warnings for the report)

    def subset(self, mask: np.ndarray) -> "SoupAlpha":
        """The alpha of the faces where mask (F,) bool."""
        if self.image_index is None:
            return SoupAlpha(self.constant[mask], notes=self.notes)
        return SoupAlpha(self.constant[mask], self.images, self.image_index[mask], self.uvs[mask], self.notes)

    @property
    def lets_light_through(self) -> bool:
        """Whether any face is not simply opaque."""
        return bool((self.constant < 1.0).any() or (self.image_index is not None and (self.image_index >= 0).any()))


@dataclass
class DrawnAlpha:
    """Per drawn face (the plan's drawn_positions order): constant (F,) float32, layer (F,)
    int32 (-1: no image), uvs (F, 3, 2) float32; images (L, S, S) float32; mode 'blend' or
    'clip' with its threshold clip."""

    constant: np.ndarray
    layer: np.ndarray
    uvs: np.ndarray
    images: np.ndarray
    mode: str
    clip: float

    @property
    def side(self) -> int:
        return int(self.images.shape[1])

    def face_alpha(self, face: np.ndarray, bary: np.ndarray) -> np.ndarray:
        """(m,) alpha at m points of drawn faces face (m,) int with barycentrics bary (m, 3):
        the constant times the image's texel at the point's UV (nearest, repeating), as the
        GPU's texelFetch reads it."""
        a = self.constant[face].astype(np.float64)
        layer = self.layer[face]
        textured = layer >= 0
        if textured.any():
            uv = np.einsum("mk,mkd->md", bary[textured], self.uvs[face[textured]].astype(np.float64))
            texel = np.clip(np.floor(np.mod(uv, 1.0) * self.side).astype(np.int64), 0, self.side - 1)
            a[textured] *= self.images[layer[textured], texel[:, 1], texel[:, 0]]
        return a

    def kept_weight(self, alpha: np.ndarray) -> np.ndarray:
        """The probability that a surface of this alpha occludes (blend: alpha; clip: 0 or 1)."""
        return alpha if self.mode == "blend" else (alpha >= self.clip).astype(np.float64)


def resampled(image: np.ndarray, side: int) -> np.ndarray:
    """(side, side) nearest resampling of an (H, W) image (texel centres)."""
    h, w = image.shape
    rows = np.minimum(((np.arange(side) + 0.5) * h / side).astype(np.int64), h - 1)
    cols = np.minimum(((np.arange(side) + 0.5) * w / side).astype(np.int64), w - 1)
    return image[rows][:, cols].astype(np.float32)


def drawn_alpha(parts: list[tuple[int, SoupAlpha | None]], mode: str, clip: float) -> DrawnAlpha | None:
    """The DrawnAlpha of drawn faces given as (face count, its soup's alpha or None: opaque)
    in drawing order, or None where nothing lets light through (the alpha passes skipped)."""
    if mode == "off" or not any(alpha is not None and alpha.lets_light_through for _n, alpha in parts):
        return None
    images = [im for _n, alpha in parts if alpha is not None for im in alpha.images]
    side = min(MAX_ALPHA_SIDE, max([max(im.shape) for im in images], default=1))
    constant, layer, uvs, stack = [], [], [], []
    for count, alpha in parts:
        textured = alpha is not None and alpha.image_index is not None
        constant.append(np.ones(count, np.float32) if alpha is None else np.asarray(alpha.constant, np.float32))
        if textured:
            layer.append(np.where(alpha.image_index >= 0, alpha.image_index + len(stack), -1).astype(np.int32))
            uvs.append(np.asarray(alpha.uvs, np.float32))
            stack += [resampled(im, side) for im in alpha.images]
        else:
            layer.append(np.full(count, -1, np.int32))
            uvs.append(np.zeros((count, 3, 2), np.float32))
    stacked = np.stack(stack) if stack else np.ones((1, 1, 1), np.float32)
    return DrawnAlpha(np.concatenate(constant), np.concatenate(layer), np.concatenate(uvs), stacked, mode, clip)


def expected_visibility(kept: list[float], occlusion: list[float]) -> float:
    """Visibility along a ray through surfaces in order, each occluding with probability
    kept[i] by occlusion[i] (1 without a max distance, the falloff's weight with one): one
    minus the expected occlusion of the first surface that is kept."""
    through, occluded = 1.0, 0.0
    for p, k in zip(kept, occlusion):
        occluded += through * p * k
        through *= 1.0 - p
    return 1.0 - occluded
