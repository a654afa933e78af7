# SPDX-License-Identifier: GPL-3.0-or-later
"""--verify: a finished bake's sampled texels re-estimated by the CPU reference
(core/bake/verify.py says what it shares with the bake and what it measures). No Blender data:
input and output are numpy, as in hao_addon.bake."""
from __future__ import annotations

from typing import Generator

import numpy as np

from .bake import BakeResult
from .replicates import replicate_sums_steps
from .core.bake.bake_run import BakeRun
from .core.bake.error_estimate import replicate_twin
from .core.bake.plan import make_plan_steps
from .core.bake.reference_baker import ReferenceBaker
from .core.bake.settings import BakeSettings
from .core.bake.targets import BakeTarget
from .core.bake.verify import VERIFY_DIRECTIONS, VERIFY_SEED, Verification, pick_cells, verification
from .core.geometry import TriangleSoup


def verify_steps(target: BakeTarget, occluders: list[TriangleSoup], settings: BakeSettings, result: BakeResult,
                 count: int) -> Generator[float, None, Verification | None]:
    """Re-estimate `count` random covered cells of `result` (the bake of target and occluders
    with settings) with the reference at VERIFY_DIRECTIONS; yields progress in [0, 1]. None
    when nothing is covered."""
    cells = pick_cells(result.covered, count, settings.seed)
    if len(cells) == 0:
        return None
    run = BakeRun(VERIFY_DIRECTIONS, (settings.seed + VERIFY_SEED) % 2**31, "reference", cells, ao_only=True)
    plan = yield from make_plan_steps(target, occluders, settings, run=run)  # a projection's rays yield progress too
    baker = ReferenceBaker(plan)
    try:
        sums_a, sums_b = yield from replicate_sums_steps(baker, plan.direction_count)
    finally:
        baker.free()
    num_a, w_a = (part.reshape(-1)[cells] for part in plan.estimator.ratio(sums_a))
    num_b, w_b = (part.reshape(-1)[cells] for part in plan.estimator.ratio(sums_b))
    seen = (w_a > 0.0) & (w_b > 0.0)  # cells the reference lights (a map texel may hold only its margin's value)
    truth = 0.5 * (num_a[seen] / w_a[seen] + num_b[seen] / w_b[seen])
    twin = replicate_twin(num_a[seen], w_a[seen], num_b[seen], w_b[seen])
    values = result.ao.reshape(-1)[cells][seen]
    return verification(values, np.clip(truth, 0.0, 1.0), twin, VERIFY_DIRECTIONS, settings.seed)
