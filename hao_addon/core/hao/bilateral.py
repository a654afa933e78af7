# SPDX-License-Identifier: GPL-3.0-or-later
"""Joint bilateral upsampling of the AO map (HAO paper, equations 5 to 8), numpy reference
of gpu_shaders/hao_bilateral.comp.

Full-resolution pixel x gets  sum_y w_d w_n w_p w_h h(y) / sum_y w_d w_n w_p w_h  over a
window of |x - y| <= m / 2 pixels along one axis, then the same along the other axis
(the separable approximation, equation 8). In the first pass h(y) = h'(y // k), the low
resolution map, and p(y), n(y) are the position and normal of the G-buffer sample that
value was computed at (its block's pick, hao_pick.glsl), with no w_h (see
joint_bilateral_upsample); in the second pass h is the first pass's output.
- w_d = w(|x - y|, m)                    (Wendland, equation 3, m = filter size)
- w_n = w(1 - <n(x), n(y)>, 2)           the paper prints 1 + <.,.>, which would give equal
                                         normals weight 0; 1 - <.,.> is the evident intent
- w_p = w(|p(x) - p(y)|, d)              d = d_max, or a range the renderer picks at
                                         unlimited distance (hao_renderer.filter_range)
- w_h = w(|h(x) - h(y)|, 1)
Background pixels (no geometry) neither receive nor give weight; they stay 1.
"""
from __future__ import annotations

import numpy as np

from ..kernels import wendland


def _pass(values: np.ndarray, positions: np.ndarray, normals: np.ndarray, valid: np.ndarray, axis: int, m: int,
          max_distance: float) -> np.ndarray:
    """One full-resolution axis with all four weights (w_h against the pixel's own value)."""
    h, w = valid.shape
    radius = m // 2
    num = np.zeros((h, w))
    den = np.zeros((h, w))
    n = valid.shape[axis]
    for d in range(-radius, radius + 1):
        sl_dst = [slice(None), slice(None)]
        sl_src = [slice(None), slice(None)]
        sl_dst[axis], sl_src[axis] = slice(max(0, -d), n - max(0, d)), slice(max(0, d), n - max(0, -d))
        dst, src = tuple(sl_dst), tuple(sl_src)
        wd = wendland(abs(d), m) if m > 0 else 1.0
        dot = (normals[dst] * normals[src]).sum(-1)
        wn = wendland(np.clip(1.0 - dot, 0.0, 2.0), 2.0)
        wp = wendland(np.linalg.norm(positions[dst] - positions[src], axis=-1), max_distance)
        wh = wendland(np.abs(values[dst] - values[src]), 1.0)
        wt = wd * wn * wp * wh * valid[src] * valid[dst]
        num[dst] += wt * values[src]
        den[dst] += wt
    out = np.where(den > 0.0, num / np.where(den > 0.0, den, 1.0), values)
    return np.where(valid, out, 1.0)


def joint_bilateral_upsample(low: np.ndarray, low_positions: np.ndarray, low_normals: np.ndarray,
                             low_valid: np.ndarray, positions: np.ndarray, normals: np.ndarray, valid: np.ndarray,
                             scale: int, filter_size: int, max_distance: float) -> np.ndarray:
    """low: (h, w) AO map with h = ceil(H / scale), low_positions, low_normals (h, w, 3) and
    low_valid (h, w) bool: the G-buffer sample each AO-map pixel stands for (hao_pick.glsl);
    positions, normals: (H, W, 3) world; valid: (H, W) bool. Returns the (H, W) filtered
    full-resolution AO.

    First pass (upsampling, along x): each pixel weighs the AO-map samples of the blocks its
    window covers by the sample's own position and normal, without the AO range weight: the
    pixel has no AO yet, and its own block's sample can lie on another surface (a floor
    pixel beside a character's silhouette took the character's AO; measured on the walking
    character over a 40 m floor). Second pass (along y): the first pass's output, with w_h."""
    H, W = valid.shape
    ys, xs = np.arange(H) // scale, np.arange(W) // scale
    up = lambda a: a[ys][:, xs].astype(np.float64)  # noqa: E731 - each pixel's block
    values, s_pos, s_nrm, s_valid = up(low), up(low_positions), up(low_normals), up(low_valid) > 0.5
    first = _upsample_pass(values, s_pos, s_nrm, s_valid, up(low), positions, normals, valid, filter_size,
                           max_distance)
    return _pass(first, positions, normals, valid, 0, filter_size, max_distance)


def _upsample_pass(values, s_pos, s_nrm, s_valid, fallback, positions, normals, valid, m, max_distance):
    """Along x: num / den of the samples' values weighted by w_d w_n w_p (see above); a pixel
    no sample matches keeps its block's value."""
    h, w = valid.shape
    radius = m // 2
    num = np.zeros((h, w))
    den = np.zeros((h, w))
    for d in range(-radius, radius + 1):
        dst = (slice(None), slice(max(0, -d), w - max(0, d)))
        src = (slice(None), slice(max(0, d), w - max(0, -d)))
        wd = wendland(abs(d), m) if m > 0 else 1.0
        dot = (normals[dst] * s_nrm[src]).sum(-1)
        wn = wendland(np.clip(1.0 - dot, 0.0, 2.0), 2.0)
        wp = wendland(np.linalg.norm(positions[dst] - s_pos[src], axis=-1), max_distance)
        wt = wd * wn * wp * s_valid[src] * valid[dst]
        num[dst] += wt * values[src]
        den[dst] += wt
    out = np.where(den > 0.0, num / np.where(den > 0.0, den, 1.0), fallback)
    return np.where(valid, out, 1.0)
