# SPDX-License-Identifier: GPL-3.0-or-later
"""Distance falloff kernels shared by the bakers, the viewport passes and the references.

AO with a maximum distance weights each occluder hit at distance t by rho(t):
accessibility = 1 - (1/pi) * integral over the hemisphere of rho(t(w)) cos(theta) dw,
where rho = 0 when the ray escapes. 'none' is the step rho = [t < d_max] (or 1 for any hit
when d_max is unlimited); 'wendland' is equation 3 of the Hybrid AO paper,
w(t, h) = (1 - t/h)^4 (4 t/h + 1) on [0, h], a C2 kernel with compact support that decays
smoothly from 1 to 0, so objects entering the range do not pop.
"""
from __future__ import annotations

import numpy as np

from .setting_spec import Choice

# The falloff setting's choices, shared by the bake and the viewport AO.
FALLOFF_CHOICES = (
    Choice("none", "None", "full occlusion up to the max distance, none beyond"),
    Choice("wendland", "Smooth (Wendland)", "fades smoothly to zero at the max distance (Hybrid AO paper, eq. 3)"),
)
FALLOFFS = tuple(c.value for c in FALLOFF_CHOICES)


def wendland(t: np.ndarray, h: float) -> np.ndarray:
    """Wendland C2 kernel (HAO paper, equation 3). t: distances (any shape), h > 0."""
    if not h > 0.0:
        raise ValueError(f"Wendland support must be positive, got {h}")
    x = np.clip(np.asarray(t, dtype=np.float64) / h, 0.0, 1.0)
    return (1.0 - x) ** 4 * (4.0 * x + 1.0)


def occlusion_weight(t: np.ndarray, max_distance: float, falloff: str) -> np.ndarray:
    """rho(t) for hit distances t (np.inf for a miss).

    max_distance <= 0 means unlimited: every hit occludes fully and falloff is ignored.
    """
    t = np.asarray(t, dtype=np.float64)
    hit = np.isfinite(t)
    if max_distance <= 0.0:
        return hit.astype(np.float64)
    if falloff == "none":
        return (hit & (t < max_distance)).astype(np.float64)
    if falloff == "wendland":
        return np.where(hit, wendland(np.where(hit, t, 0.0), max_distance), 0.0)
    raise ValueError(f"unknown falloff '{falloff}', expected one of {FALLOFFS}")
