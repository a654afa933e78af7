# SPDX-License-Identifier: GPL-3.0-or-later
"""Joint bilateral upsampling of the AO map (HAO paper, equations 5 to 8), numpy reference
of gpu_shaders/hao_bilateral.comp.

Full-resolution pixel x gets  sum_y w_d w_n w_p w_h h(y) / sum_y w_d w_n w_p w_h  over a
window of |x - y| <= m / 2 pixels along one axis, then the same along the other axis
(the separable approximation, equation 8). In the first pass h(y) = h'(y // k), the low
resolution map; in the second pass h is the first pass's output.
- w_d = w(|x - y|, m)                    (Wendland, equation 3, m = filter size)
- w_n = w(1 - <n(x), n(y)>, 2)           the paper prints 1 + <.,.>, which would give equal
                                         normals weight 0; 1 - <.,.> is the evident intent
- w_p = w(|p(x) - p(y)|, d_max)
- w_h = w(|h(x) - h(y)|, 1)
Background pixels (no geometry) neither receive nor give weight; they stay 1.
"""
from __future__ import annotations

import numpy as np

from ..kernels import wendland


def _pass(values: np.ndarray, positions: np.ndarray, normals: np.ndarray, valid: np.ndarray,
          centre_values: np.ndarray, axis: int, m: int, max_distance: float) -> np.ndarray:
    h, w = valid.shape
    radius = m // 2
    num = np.zeros((h, w))
    den = np.zeros((h, w))
    for d in range(-radius, radius + 1):
        sl_dst = [slice(None), slice(None)]
        sl_src = [slice(None), slice(None)]
        n = valid.shape[axis]
        if d >= 0:
            sl_dst[axis], sl_src[axis] = slice(0, n - d), slice(d, n)
        else:
            sl_dst[axis], sl_src[axis] = slice(-d, n), slice(0, n + d)
        dst, src = tuple(sl_dst), tuple(sl_src)
        wd = wendland(abs(d), m) if m > 0 else 1.0
        dot = (normals[dst] * normals[src]).sum(-1)
        wn = wendland(np.clip(1.0 - dot, 0.0, 2.0), 2.0)
        wp = wendland(np.linalg.norm(positions[dst] - positions[src], axis=-1), max_distance)
        wh = wendland(np.abs(centre_values[dst] - values[src]), 1.0)
        wt = wd * wn * wp * wh * valid[src] * valid[dst]
        num[dst] += wt * values[src]
        den[dst] += wt
    out = np.where(den > 0.0, num / np.where(den > 0.0, den, 1.0), centre_values)
    return np.where(valid, out, 1.0)


def joint_bilateral_upsample(low: np.ndarray, positions: np.ndarray, normals: np.ndarray, valid: np.ndarray,
                             scale: int, filter_size: int, max_distance: float) -> np.ndarray:
    """low: (h, w) AO map with h = ceil(H / scale); positions, normals: (H, W, 3) world;
    valid: (H, W) bool. Returns the (H, W) filtered full-resolution AO."""
    H, W = valid.shape
    ys, xs = np.arange(H) // scale, np.arange(W) // scale
    up = low[ys][:, xs].astype(np.float64)
    first = _pass(up, positions, normals, valid, up, 1, filter_size, max_distance)
    return _pass(first, positions, normals, valid, first, 0, filter_size, max_distance)
