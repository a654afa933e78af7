# SPDX-License-Identifier: GPL-3.0-or-later
"""The floor check's snapshots of a bake's partial map (hao_addon/floor_check.py): what a
replicate's first directions make of each texel, kept until the checked texels are known.

A snapshot is taken twice a round, mid-bake, before those texels are drawn, so it must keep
what any texel could need, as cheaply as the baker allows:
- MapSnapshot: the partial map value (one float32 a texel), from a baker's map sums (the
  scatter's splats). Two at 4096^2 keep 134 MB and cost a whole-map reduction each.
- EntrySnapshot: a list baker's partial value per entry (the gather's texel list), summed per
  texel only at the cells asked for. The gather's map sums add up every entry per texel (1.7-2.1
  s at 4096^2, 16M entries); this keeps the entries' values as they are read back.
Both give the same values at the same cells (tests/test_whole_error.py)."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .estimators import Estimator


def sums_value(estimator: Estimator, sums: np.ndarray) -> np.ndarray:
    """(...) float32 partial map value numerator / W of sums (..., channels), NaN where W = 0."""
    numerator, weight = estimator.ratio(sums)
    lit = weight > 0.0
    return np.where(lit, np.divide(numerator, weight, out=np.zeros(weight.shape), where=lit), np.nan
                    ).astype(np.float32)


@dataclass(frozen=True)
class MapSnapshot:
    """values: (*output_shape) float32 partial map value, NaN where unlit."""

    values: np.ndarray

    @classmethod
    def of(cls, estimator: Estimator, sums: np.ndarray) -> "MapSnapshot":
        """From a baker's map sums (*output_shape, channels)."""
        return cls(sums_value(estimator, sums))

    def at(self, cells: np.ndarray) -> np.ndarray:
        """(n,) float64 values at flat cells (n,)."""
        return self.values.reshape(-1)[cells].astype(np.float64)


@dataclass(frozen=True)
class EntrySnapshot:
    """values: (m,) float32 each entry's own partial value (NaN where no direction lit it);
    cell: (m,) each entry's flat output index; cell_count: the output's size. A texel's value
    is the mean of its lit entries' (estimators.texel_sums weighs each lit entry 1)."""

    values: np.ndarray
    cell: np.ndarray
    cell_count: int

    @classmethod
    def of(cls, estimator: Estimator, sums: np.ndarray, cell: np.ndarray, cell_count: int) -> "EntrySnapshot":
        """From a list baker's entry sums (m, channels)."""
        return cls(sums_value(estimator, sums), cell, cell_count)

    def at(self, cells: np.ndarray) -> np.ndarray:
        """(n,) float64 values at sorted flat cells (n,), NaN where no entry is lit."""
        wanted = np.zeros(self.cell_count, bool)
        wanted[cells] = True
        keep = wanted[self.cell]
        values = self.values[keep].astype(np.float64)
        lit = np.isfinite(values)
        index = np.searchsorted(cells, self.cell[keep][lit])
        total = np.bincount(index, values[lit], minlength=len(cells))
        count = np.bincount(index, minlength=len(cells))
        return np.divide(total, count, out=np.full(len(cells), np.nan), where=count > 0)
