# SPDX-License-Identifier: GPL-3.0-or-later
"""The estimator of a bake (receivers x estimator x output): what each light direction adds to
a receiver's sums, and what the map is made of them (pure numpy).

Every baker evaluates, per receiver and direction omega, the hemisphere weight w (about the
shading normal, times the receiver's exact 1 / S) and the visibility V in [0, 1] (its own
business: depth maps, splats or rays), and hands (w, V, omega) to the estimator, which turns
them into `channels` floats to sum. The last channel is always the weight sum W = sum(w), the
coverage every output is normalized and dilated by (core/bake/seams.py).

The GPU passes get the same term as GLSL (gpu_shaders/bake_estimator.glsl, selected by the
estimator's define; the channel count arrives as ESTIMATOR_CHANNELS), the reference baker
calls terms() (core/bake/reference_baker.py): one definition per estimator, and the twins
differ only in how they find V. A new output of the same bake (bent normals: sum(w V omega)
besides sum(w V)) is a new Estimator with its channels, GLSL term and finish().
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..geometry import unit_vectors


@dataclass(frozen=True)
class Estimator:
    """name: what the map is; channels: the per-receiver sums, in order, the weight sum W
    last; define: the GLSL define selecting its term."""

    name: str
    channels: tuple[str, ...]
    define: str

    @property
    def channel_count(self) -> int:
        return len(self.channels)

    def terms(self, weight: np.ndarray, visible: np.ndarray, omega: np.ndarray) -> np.ndarray:
        """(n, channel_count) float64: what direction omega (3,) adds to n receivers of weight
        (n,) and visibility (n,)."""
        raise NotImplementedError

    def ratio(self, sums: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(numerator, W) of the scalar map, each (...) float64, from sums (..., channel_count):
        the map is numerator / W where W > 0 (core/bake/seams.finalize_map)."""
        raise NotImplementedError


class AmbientOcclusion(Estimator):
    """Accessibility: sum(w V) / sum(w), 1 where nothing occludes (the paper's equation 8 for
    the scatter, a point sample of the same integral for the gather and the reference)."""

    def __init__(self) -> None:
        super().__init__("ambient occlusion", ("visible_weight", "weight"), "ESTIMATOR_AMBIENT_OCCLUSION")

    def terms(self, weight: np.ndarray, visible: np.ndarray, omega: np.ndarray) -> np.ndarray:
        return np.stack([weight * visible, weight], axis=-1)

    def ratio(self, sums: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        return sums[..., 0], sums[..., 1]


class BentNormals(Estimator):
    """Accessibility and the bent normal from one set of sums: sum(w V) and sum(w V omega)
    (the cosine-weighted mean unoccluded direction), sum(w omega) (the same mean over the whole
    hemisphere: the fallback direction where every direction is blocked) and sum(w)."""

    def __init__(self) -> None:
        super().__init__("ambient occlusion and bent normals",
                         ("visible_weight", "bent_x", "bent_y", "bent_z", "open_x", "open_y", "open_z", "weight"),
                         "ESTIMATOR_BENT_NORMALS")

    def terms(self, weight: np.ndarray, visible: np.ndarray, omega: np.ndarray) -> np.ndarray:
        seen = weight * visible
        omega = np.asarray(omega, np.float64)
        return np.concatenate([seen[:, None], seen[:, None] * omega, weight[:, None] * omega, weight[:, None]],
                              axis=1)

    def ratio(self, sums: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        return sums[..., 0], sums[..., 7]

    def bent(self, sums: np.ndarray) -> np.ndarray:
        """(..., 3) float64 unit bent normals from sums (..., 8), in the directions' space:
        sum(w V omega) normalized, or sum(w omega) normalized where nothing is visible; zero
        where no direction has weight."""
        return unit_vectors(np.where((sums[..., 0] > 0.0)[..., None], sums[..., 1:4], sums[..., 4:7]))



AMBIENT_OCCLUSION = AmbientOcclusion()
BENT_NORMALS = BentNormals()


def texel_sums(texel: np.ndarray, sums: np.ndarray, shape: tuple[int, ...]) -> np.ndarray:
    """(*shape, C) float64: receivers' sums (n, C) added up per flat output index (n,) (a
    texel y * size + x of a (size, size) map, or a colour attribute's element), each
    receiver's first divided by its own weight sum W (the last channel).

    That division is the exact normalization per receiver: every receiver that some direction
    lights weighs 1 in its texel, whatever the discrete hemisphere weight sum S of its shading
    normal, so any positive per-receiver scale of the weights (Receivers.inv_s, an interpolated
    1 / S that keeps the GPU's float32 sums near 1) cancels. A receiver no direction lights
    (W = 0) adds nothing."""
    normalized = _normalized(sums)
    cells = int(np.prod(shape))
    return np.stack([np.bincount(texel, weights=normalized[:, c], minlength=cells)
                     for c in range(sums.shape[1])], axis=-1).reshape(*shape, sums.shape[1])


def texel_sums_at(texel: np.ndarray, sums: np.ndarray, cells: np.ndarray) -> np.ndarray:
    """(k, C) float64: texel_sums at the sorted flat indices cells (k,) alone (receivers
    elsewhere are left out): a few texels' sums without a map the size of the output (at
    4096^2 six of those took 1.1 s of a bake's contacts and floor check)."""
    normalized = _normalized(sums)
    at = np.clip(np.searchsorted(cells, texel), 0, max(len(cells) - 1, 0))
    inside = (cells[at] == texel) if len(cells) else np.zeros(len(texel), bool)
    return np.stack([np.bincount(at[inside], weights=normalized[inside, c], minlength=len(cells))
                     for c in range(sums.shape[1])], axis=-1).reshape(len(cells), sums.shape[1])


def _normalized(sums: np.ndarray) -> np.ndarray:
    """Each receiver's sums (n, C) divided by its own weight sum W (the last channel); 0 where W = 0."""
    weight = sums[:, -1:]
    return np.divide(sums, weight, out=np.zeros_like(sums), where=weight > 0.0)
