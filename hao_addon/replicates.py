# SPDX-License-Identifier: GPL-3.0-or-later
"""A baker's directions run as the error estimate's replicates (core/bake/error_estimate.py),
each summed apart: shared by bakes, their floor checks and verifications."""
from __future__ import annotations

from typing import Generator

from .core.bake.probe_snapshot import EntrySnapshot, MapSnapshot
from .core.directions import replicate_sizes


def probe_snapshot(baker) -> MapSnapshot | EntrySnapshot:
    """The baker's partial map as the floor check keeps it: its own probe_snapshot() where it
    has a cheaper one (the gather's entries), else a MapSnapshot of its sums."""
    own = getattr(baker, "probe_snapshot", None)
    return own() if own is not None else MapSnapshot.of(baker.plan.estimator, baker.accumulated())


def replicate_sums_steps(baker, count: int, start: float = 0.0, snapshots: dict | None = None
                         ) -> Generator[float, None, tuple]:
    """Run a baker's `count` directions, each replicate summed apart (core/bake/error_estimate.py):
    (the first replicate's sums or None when there is one, the last one's), each
    (*plan.output_shape, channels). Yields progress from start to 1. snapshots: {step: None}
    to fill with the running replicate's probe_snapshot() after that many steps (the floor
    check's partial map, core/bake/probe_snapshot.py)."""
    split = replicate_sizes(count)[0]  # the second replicate's first direction
    sums_a = None
    snapshots = {} if snapshots is None else snapshots
    for i in range(count):
        if i == split:
            sums_a = baker.accumulated()
            if i in snapshots:  # read anyway
                snapshots[i] = MapSnapshot.of(baker.plan.estimator, sums_a)
            baker.restart()
        elif i in snapshots:
            snapshots[i] = probe_snapshot(baker)
        baker.run_direction(i)
        yield start + (1.0 - start) * (i + 1) / count
    sums_b = baker.accumulated()
    if count in snapshots:
        snapshots[count] = MapSnapshot.of(baker.plan.estimator, sums_b)
    return sums_a, sums_b
