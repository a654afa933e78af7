# SPDX-License-Identifier: GPL-3.0-or-later
"""Timing for the benchmarks on a shared, noisy machine."""
from __future__ import annotations

import statistics
import time
from typing import Callable

# A run under REPEAT_UNDER_S seconds is repeated to REPEATS runs and its median kept: one
# short run on a 2-core machine shared with other work can take 1.5x its quiet time, and
# which of two bakers it hits decides a ratio. Longer runs are timed once (noise is a
# smaller share of them, and three 1024-sample Cycles bakes would take 15 minutes).
REPEATS = 3
REPEAT_UNDER_S = 30.0


def median_seconds(run: Callable[[], object], repeat_under_s: float = REPEAT_UNDER_S) -> tuple[float, object]:
    """(median wall seconds, the last run's result) of run(), repeated as described above."""
    times, result = [], None
    for _ in range(REPEATS):
        t = time.perf_counter()
        result = run()
        times.append(time.perf_counter() - t)
        if times[0] >= repeat_under_s:
            break
    return statistics.median(times), result
