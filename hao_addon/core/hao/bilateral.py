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


def _pass(centre: tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray],
          samples: tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray], axis: int, m: int, max_distance: float,
          range_weight: bool) -> np.ndarray:
    """One axis. centre: (values, positions, normals, valid) of the pixels filtered (values:
    kept where no sample matches); samples: the same of what each pixel offers its
    neighbours; range_weight: include w_h against the centre's value."""
    c_values, c_pos, c_nrm, c_valid = centre
    values, positions, normals, valid = samples
    num = np.zeros(c_valid.shape)
    den = np.zeros(c_valid.shape)
    n = c_valid.shape[axis]
    for d in range(-(m // 2), m // 2 + 1):
        sl_dst = [slice(None), slice(None)]
        sl_src = [slice(None), slice(None)]
        sl_dst[axis], sl_src[axis] = slice(max(0, -d), n - max(0, d)), slice(max(0, d), n - max(0, -d))
        dst, src = tuple(sl_dst), tuple(sl_src)
        wd = wendland(abs(d), m) if m > 0 else 1.0
        dot = (c_nrm[dst] * normals[src]).sum(-1)
        wt = wd * wendland(np.clip(1.0 - dot, 0.0, 2.0), 2.0) \
            * wendland(np.linalg.norm(c_pos[dst] - positions[src], axis=-1), max_distance) * valid[src] * c_valid[dst]
        if range_weight:
            wt = wt * wendland(np.abs(c_values[dst] - values[src]), 1.0)
        num[dst] += wt * values[src]
        den[dst] += wt
    out = np.where(den > 0.0, num / np.where(den > 0.0, den, 1.0), c_values)
    return np.where(c_valid, out, 1.0)


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
    character over a 40 m floor); a pixel no sample matches keeps its block's value. Second
    pass (along y): the first pass's output, with w_h."""
    H, W = valid.shape
    ys, xs = np.arange(H) // scale, np.arange(W) // scale
    up = lambda a: a[ys][:, xs].astype(np.float64)  # noqa: E731 - each pixel's block
    blocks = up(low)
    first = _pass((blocks, positions, normals, valid),
                  (blocks, up(low_positions), up(low_normals), up(low_valid) > 0.5), 1, filter_size, max_distance,
                  range_weight=False)
    full = (first, positions, normals, valid)
    return _pass(full, full, 0, filter_size, max_distance, range_weight=True)
