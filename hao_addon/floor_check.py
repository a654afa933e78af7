# SPDX-License-Identifier: GPL-3.0-or-later
"""A GPU bake's visibility floor, measured while it bakes: what its visibility test (depth maps,
their resolution and bias, the texel list's choice of face on an edge) gets wrong, which more
directions never remove. No Blender data: numpy in and out, as hao_addon.bake.

How: at up to FLOOR_TEXELS sampled texels, the map's partial sums after the first
probe_half() directions of each replicate (a random subset of it: core/directions.probe_first,
which the gather bakes first) are read back (a probe), and the CPU reference traces exactly
those directions from the bake's own sample points. The difference holds no direction noise,
only the visibility test's error, and it estimates the floor proper for any direction count:
under the random rotation every direction of any subset is uniform on the sphere, so the
difference's expectation is the same for a few directions as for all of them
(core/bake/error_estimate.with_floor takes the part the two replicates share). A probe of a
part of the directions lets many texels be checked for few rays: the floor is
heavy-tailed (Spot at 48^2: two texels of 1118, on triangles a tenth of a light-view pixel,
held 60 % of its square), and 256 texels missed such texels, stating half the measured error.

Why it is needed: against an exact ray-traced truth (bench/floor_bench.py) the gather's maps
stop converging at RMSE 0.0015-0.005 (128^2, flat), where the twins alone stated 0.0005-0.0009.
"""
from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Generator

import numpy as np

from .core.bake.abilities import declaration
from .core.bake.plan import BakePlan
from .core.bake.receivers import Receivers
from .core.bake.verify import pick_cells
from .core.directions import probe_half, replicate_sizes

# Texels checked: about 2 per direction of the bake, between MIN_FLOOR_TEXELS and FLOOR_TEXELS
# (all covered texels of a smaller map). With probe_half() directions per replicate that is
# 131k rays at 256 directions, 524k at 1024, 2.1M from 4096 on (about half of them traced,
# above the surface; 0.4, 1.5 and 6 s here: about an eighth of a 1024^2 gather bake's time).
FLOOR_TEXELS = 1024
MIN_FLOOR_TEXELS = 256
TEXELS_PER_DIRECTION = 2
FLOOR_SEED = 7907  # the sample's seed, apart from the verification's
# Rays from the GPU's sample points start this many light-view pixels off the surface. A
# texel-list point lies on its face's plane, but the rasterizer's snapping (1/256 of a texel
# in UV space) can put it just past the face's edge, where the neighbouring face at an angle
# lies above it: from the reference's own offset (1e-6 of the scene) every ray then left
# through that face's back (the rocker arm at 128^2: one texel of 256 read 0.90 too dark, and
# the floor's RMSE 0.057 where 0.004 was measured). The snapping puts a point at most 1/180 of a
# pixel (view samples 2) past its edge; the gather's depth slack is 64 times this offset.
START_OFFSET_PIXELS = 1.0 / 128.0


@dataclass
class FloorProbe:
    """A round's partial sums at the sample: plan: the round's; half: directions per
    replicate; steps: (2, half) the bake's direction indices of each replicate's first half
    steps; values: (2, n) each replicate's partial map value at the sample's cells (NaN where
    unlit)."""

    plan: BakePlan
    half: int
    steps: np.ndarray
    values: np.ndarray


def floor_texel_count(directions: int) -> int:
    """How many texels a bake of `directions` checks."""
    return int(np.clip(TEXELS_PER_DIRECTION * directions, MIN_FLOOR_TEXELS, FLOOR_TEXELS))


def probe_steps(method: str, count: int, best: int) -> dict | None:
    """{step: None} snapshots (replicate_sums_steps) of a round of `count` directions by
    `method` when its probe would hold more directions than `best` (the largest so far), else
    None. A probe is each replicate's first probe_half(count) steps."""
    if declaration(method).floor_unchecked or count < 2:
        return None
    split = replicate_sizes(count)[0]
    half = probe_half(count)
    if half <= best:
        return None
    return {half: None, split + half: None}  # (a step equal to count: the replicate's end)


def floor_sample(method: str, covered: np.ndarray, baker, directions: int, seed: int
                 ) -> tuple[np.ndarray, Receivers] | None:
    """(cells (n,) sorted, the baker's own receivers there) of floor_texel_count(directions)
    random covered cells, taken from a live baker of `method` (its sample_receivers); None where
    the method's floor is not measured (abilities.floor_unchecked)."""
    if declaration(method).floor_unchecked or not hasattr(baker, "sample_receivers"):
        return None
    cells = pick_cells(covered, floor_texel_count(directions), (seed + FLOOR_SEED) % 2**31)
    return cells, baker.sample_receivers(cells)


def take_probe(plan: BakePlan, baker, count: int, snapshots: dict, cells: np.ndarray) -> FloorProbe:
    """The FloorProbe of a round from its snapshots (probe_steps) at `cells`."""
    split = replicate_sizes(count)[0]
    first, second = sorted(snapshots)
    half = first
    order = np.asarray(getattr(baker, "direction_order", np.arange(count)))
    values = np.full((2, len(cells)), np.nan)
    for k, step in enumerate((first, second)):
        numerator, w = (part.reshape(-1)[cells] for part in plan.estimator.ratio(snapshots[step]))
        lit = w > 0.0
        values[k, lit] = numerator[lit] / w[lit]
    return FloorProbe(plan, half, np.stack([order[:half], order[split:split + half]]), values)


def floor_steps(probe: FloorProbe, sample: tuple[np.ndarray, Receivers]
                ) -> Generator[float, None, tuple[np.ndarray, np.ndarray, np.ndarray] | None]:
    """(cells (n,), floor_a (n,), floor_b (n,)): each replicate's partial value minus the
    reference's along the same directions from the same points; None where no cell is lit in
    both. Yields progress in [0, 1]."""
    from .core.bake.reference_baker import ReferenceBaker  # deferred: mathutils comes with bpy
    cells, receivers = sample
    plan = replace(probe.plan, cells=cells)
    exact = np.full((2, len(cells)), np.nan)
    for k in range(2):
        baker = ReferenceBaker(plan, receivers, START_OFFSET_PIXELS * plan.pixel_size)
        try:
            for i, index in enumerate(probe.steps[k]):
                baker.run_direction(int(index))
                yield (k * probe.half + i + 1) / (2 * probe.half)
            numerator, w = (part.reshape(-1)[cells] for part in plan.estimator.ratio(baker.accumulated()))
        finally:
            baker.free()
        lit = w > 0.0
        exact[k, lit] = numerator[lit] / w[lit]
    seen = np.isfinite(exact).all(axis=0) & np.isfinite(probe.values).all(axis=0)
    if not seen.any():
        return None
    floor = np.clip(probe.values[:, seen], 0.0, 1.0) - np.clip(exact[:, seen], 0.0, 1.0)
    return cells[seen], floor[0], floor[1]
