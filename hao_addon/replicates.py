# SPDX-License-Identifier: GPL-3.0-or-later
"""A baker's directions run as the error estimate's replicates (core/bake/error_estimate.py),
each summed apart: shared by bakes, their floor checks and verifications."""
from __future__ import annotations

from typing import Callable, Generator

import numpy as np

from .core.directions import replicate_sizes


def replicate_sums_steps(baker, count: int, start: float = 0.0, snapshots: dict | None = None,
                         snapshot: Callable[[np.ndarray], np.ndarray] = lambda sums: sums
                         ) -> Generator[float, None, tuple]:
    """Run a baker's `count` directions, each replicate summed apart (core/bake/error_estimate.py):
    (the first replicate's sums or None when there is one, the last one's), each
    (*plan.output_shape, channels). Yields progress from start to 1. snapshots: {step: None}
    to fill with snapshot(the running replicate's sums) after that many steps (the floor
    check's partial map, hao_addon/floor_check.probe_map)."""
    split = replicate_sizes(count)[0]  # the second replicate's first direction
    sums_a = None
    snapshots = {} if snapshots is None else snapshots
    for i in range(count):
        if i in snapshots or i == split:  # the first replicate's end may be a snapshot too
            sums = baker.accumulated()
            if i in snapshots:
                snapshots[i] = snapshot(sums)
            if i == split:
                sums_a = sums
                baker.restart()
        baker.run_direction(i)
        yield start + (1.0 - start) * (i + 1) / count
    sums_b = baker.accumulated()
    if count in snapshots:
        snapshots[count] = snapshot(sums_b)
    return sums_a, sums_b
