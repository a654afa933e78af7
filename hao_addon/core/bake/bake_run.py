# SPDX-License-Identifier: GPL-3.0-or-later
"""What one run of the bakers bakes beside the user's settings (pure data).

A bake to an error runs rounds of their own direction counts and seeds, a verification runs
the reference at its own count and seed over sampled cells, a thickness bake needs an ability
its settings do not name. Each is a BakeRun handed to the plan (core/bake/plan.py), which
chooses the method from it once; the user's settings are never rewritten to carry them.
"""
from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from .settings import BakeSettings


@dataclass(frozen=True)
class BakeRun:
    """directions: how many light directions (D); seed: their rotation and the light views'
    jitter. method: the method asked ('auto': the plan chooses from what the bake needs).
    cells: the output cells (flat indices into BakePlan.output_shape) to bake, or None for
    all. ao_only: the AO's sums alone (no bent normals' sums, which a verification does not
    read). needs: abilities the bake needs beyond its settings' (core/bake/abilities.py:
    'thickness' for the inner bake of a thickness map)."""

    directions: int
    seed: int
    method: str = "auto"
    cells: np.ndarray | None = None
    ao_only: bool = False
    needs: frozenset[str] = frozenset()
    # (k, 4) world spheres the light views are cropped to (a re-bake by difference draws and
    # reads only the pixels an edit can change: hao_addon/rebake_difference.py), or None.
    window_spheres: np.ndarray | None = None

    @classmethod
    def of(cls, settings: BakeSettings, needs: frozenset[str] = frozenset()) -> "BakeRun":
        """The run the settings ask for: their directions, seed and method, every cell."""
        return cls(settings.directions, settings.seed, settings.method, needs=needs)

    def with_cells(self, cells: np.ndarray | None) -> "BakeRun":
        return replace(self, cells=cells)

    def with_windows(self, spheres: np.ndarray | None) -> "BakeRun":
        return replace(self, window_spheres=spheres)
