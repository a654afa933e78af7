# SPDX-License-Identifier: GPL-3.0-or-later
"""A GPU bake's visibility floor, measured while it bakes: what its visibility test (depth maps,
their resolution and bias, the texel list's choice of face on an edge) gets wrong, which more
directions never remove. No Blender data: numpy in and out, as hao_addon.bake.

How: at floor_texel_count() sampled texels, the map's partial sums after the first
probe_half() directions of each replicate (a random subset of it: core/directions.probe_first,
which the GPU bakers bake first) are read back (a probe), and the CPU reference traces exactly
those directions from the bake's own sample points (the gather's texel list; for the
scatter, whose texels are area averages, new random points of each texel's area for each
replicate). The difference holds no direction noise, only the visibility test's error (and for
the scatter the points' own offset from the area average, which the replicates do not share),
and it estimates the floor proper for any direction count:
under the random rotation every direction of any subset is uniform on the sphere, so the
difference's expectation is the same for a few directions as for all of them
(core/bake/error_estimate.with_floor takes the part the two replicates share; the texels
with the largest probe floors are checked again along all their round's directions, where the
part that changes with the rotation is smaller: REFINED_SHARE). A probe of a
part of the directions lets many texels be checked for few rays: the floor is
heavy-tailed (Spot at 48^2: two texels of 1118, on triangles a tenth of a light-view pixel,
held 60 % of its square), and 256 texels missed such texels, stating half the measured error.
Where a baker can tell which texels are at risk (the gather: a shading normal against its
face), each of them is checked, and the sample weighs every texel by those it stands for
(FloorSample).

Why it is needed: against an exact ray-traced truth (bench/floor_bench.py) the gather's maps
stop converging at RMSE 0.0015-0.005 (128^2, flat), where the twins alone stated 0.0005-0.0009.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Generator

import numpy as np

from .core.bake.abilities import declaration
from .core.bake.plan import BakePlan
from .core.bake.projection import DistanceCast
from .core.bake.probe_snapshot import sums_value
from .core.bake.receivers import Receivers
from .core.bake.verify import pick_cells
from .core.directions import probe_half, replicate_sizes
from .core.steps import relay

# Texels checked: as many as FLOOR_RAYS_PER_DIRECTION rays per direction of the bake buy
# (at most FLOOR_RAYS_MAX) with probe_half() directions per replicate, at least
# MIN_FLOOR_TEXELS, and every covered texel of a smaller map. That is 1024 texels at 256
# directions, 2048 at 1024, 4096 at 4096 and 16384 from 16384 on: 131k, 524k, 2.1M and 8.4M
# rays, about half of them traced (above the surface; BVH casts ran at 834k in 1.7 s here).
# The floor is heavy-tailed, so the texels count, not the rays per texel (core/directions.py,
# PROBE_MIN). The scatter traces AREA_POINTS (bake_scatter.py) points a texel.
FLOOR_RAYS_PER_DIRECTION = 512
FLOOR_RAYS_MAX = 1 << 23
MIN_FLOOR_TEXELS = 256
FLOOR_SEED = 7907  # the sample's seed, apart from the verification's
# Rays from the GPU's sample points start this many light-view pixels off the surface. A
# texel-list point lies on its face's plane, but the rasterizer's snapping (1/256 of a texel
# in UV space) can put it just past the face's edge, where the neighbouring face at an angle
# lies above it: from the reference's own offset (1e-6 of the scene) every ray then left
# through that face's back (the rocker arm at 128^2: one texel of 256 read 0.90 too dark, and
# the floor's RMSE 0.057 where 0.004 was measured). The snapping puts a point at most 1/180 of a
# pixel (view samples 2) past its edge; the gather's depth slack is 64 times this offset.
START_OFFSET_PIXELS = 1.0 / 128.0


# The probe's floors hold, besides the floor proper that both replicates share, a part that
# changes with the rotation (in the twins already; it falls as 1/sqrt(probe directions)), and
# in a few texels that part is large: Spot at 48^2, 4096 directions, every texel checked,
# stated 0.68-1.12x the measured RMSE over seeds 0-7, as a handful of texels whose replicates
# read -0.07 and +0.06 swung the shared part's mean. The REFINED_SHARE of checked texels with
# the largest probe floors are checked again along all their round's directions, where that
# part is sqrt(8) smaller (at most the probe's own rays again).
REFINED_SHARE = 1.0 / 16.0


# A bake to an error whose visibility floor has a p99 above this share of its target stops
# adding directions: they cannot bring it there (the report says so, and what to raise).
FLOOR_REACH = 0.9
# A floor this many times the direction noise (and above FLOOR_NOTICED RMSE) is said, with
# the share of the checked texels it lies in: what the light views cannot resolve.
FLOOR_OVER_NOISE = 2.0
FLOOR_NOTICED = 0.005
FLOOR_TEXEL = 0.05  # a checked texel holds the floor where both replicates are this far off


def floor_warnings(name: str, twins, whole, target: float, floors: tuple[np.ndarray, np.ndarray]) -> list[str]:
    """The warnings of a bake's whole error `whole` (with_floor of the twins' `twins`; each an
    ErrorEstimate) against its target (0: none), given the checked texels' floors (floor_a,
    floor_b): a floor far above the direction noise, where it lies; a target missed, why."""
    out = []
    if whole.floor_rmse > max(FLOOR_OVER_NOISE * twins.rmse, FLOOR_NOTICED):
        share = float(np.mean(np.minimum(np.abs(floors[0]), np.abs(floors[1])) > FLOOR_TEXEL))
        out.append(f"'{name}': its visibility floor ({whole.floor_rmse:.2g} RMSE) is {whole.floor_rmse / twins.rmse:.2g}x "
                   f"its direction noise, in {100.0 * share:.2g} % of its texels: surfaces nearer each other or thinner "
                   f"than a light-view pixel; more directions will not lower it: raise View Samples or bake with the "
                   f"reference")
    if target > 0.0 and whole.p99 > target and not whole.capped:
        why = (f"its visibility floor ({whole.floor_p99:.2g} p99) does not fall with directions; raise View "
               f"Samples or bake with the reference" if whole.floor_p99 >= FLOOR_REACH * target else
               f"with its visibility floor ({whole.floor_p99:.2g} p99) it landed above; raise the target or "
               f"bake again with a larger Quality")
        out.append(f"'{name}': the p99 error {whole.p99:.2g} is above the target {target:.2g}: {why}")
    return out


@dataclass
class FloorProbe:
    """A round's partial sums at the sample: plan: the round's; half: directions per
    replicate; steps: (2, half) the bake's direction indices of each replicate's first half
    steps; values: (2, n) each replicate's partial map value at the sample's cells (NaN where
    unlit); full_steps: each replicate's every direction index of the round; full_values:
    (2, n) each replicate's value at the cells after all of them."""

    plan: BakePlan
    half: int
    steps: np.ndarray
    values: np.ndarray
    full_steps: tuple[np.ndarray, np.ndarray]
    full_values: np.ndarray


def floor_texel_count(directions: int) -> int:
    """How many texels a bake of `directions` checks (fewer where the map covers fewer)."""
    rays = min(FLOOR_RAYS_PER_DIRECTION * directions, FLOOR_RAYS_MAX)
    return max(MIN_FLOOR_TEXELS, rays // (2 * probe_half(max(directions, 2))))


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


@dataclass(frozen=True)
class FloorSample:
    """The texels a bake's floor is checked at, a sample stratified in two: every texel at risk
    (the baker's at_risk_cells, at most a quarter of the sample) and random others. cells: (n,)
    sorted flat indices; receivers: the baker's own receivers there for each replicate;
    at_risk: (n,) bool, the first stratum; population: (texels at risk, others) among the
    texels the error covers, so that each checked texel stands for its stratum's share."""

    cells: np.ndarray
    receivers: tuple[Receivers, Receivers]
    at_risk: np.ndarray
    population: tuple[int, int]

    def weights(self, seen: np.ndarray) -> np.ndarray:
        """(seen.sum(),) each seen cell's weight: its stratum's population over the stratum's
        seen cells (seen: (n,) bool, the cells checked)."""
        out = np.zeros(int(seen.sum()))
        risk = self.at_risk[seen]
        for stratum, population in ((risk, self.population[0]), (~risk, self.population[1])):
            if stratum.any():
                out[stratum] = population / stratum.sum()
        return out

    def part(self, keep: np.ndarray) -> "FloorSample":
        """The sample at `keep` (indices into cells, sorted)."""
        cells = self.cells[keep]
        return FloorSample(cells, tuple(r.subset(np.isin(r.texel, cells)) for r in self.receivers),
                           self.at_risk[keep], self.population)

    def thinning(self, count: int, rng: np.random.Generator) -> np.ndarray | None:
        """(k,) sorted indices into cells of a sample of `count` cells: every texel at risk and
        random others (a random part of the random stratum is a random sample of it too); None
        where the sample holds no more than `count`."""
        if len(self.cells) <= count:
            return None
        risky, others = np.flatnonzero(self.at_risk), np.flatnonzero(~self.at_risk)
        chosen = rng.choice(others, size=min(max(count - len(risky), 0), len(others)), replace=False)
        return np.sort(np.concatenate([risky, chosen]))


def floor_sample(method: str, covered: np.ndarray, baker, directions: int, seed: int) -> FloorSample | None:
    """A FloorSample of floor_texel_count(directions) covered cells, taken from a live baker of
    `method` (its sample_receivers: the gather's sample points, the same for both; for the
    scatter (FRESH_DRAWS) new random points of each texel's area per replicate, so that what
    they miss of the area average is noise the replicates do not share); None where the
    method's floor is not measured (abilities.floor_unchecked).

    Texels at risk are rare and there the floor is large (the bunny at 128^2, smooth: one of
    6412 texels, 0.92 off, was the whole rise of the gather's measured RMSE from 0.0053 to
    0.0125; a random sample checked it at 1024 directions, stating 1.7x, and missed it at 4096,
    stating 0.28x), so each is checked and stands for itself alone."""
    if declaration(method).floor_unchecked or not hasattr(baker, "sample_receivers"):
        return None
    wanted = floor_texel_count(directions)
    covered = np.asarray(covered, bool).reshape(-1)
    risky = getattr(baker, "at_risk_cells", lambda: np.zeros(0, np.int64))()
    risky = risky[covered[risky]] if len(risky) else risky
    population = (len(risky), int(covered.sum()) - len(risky))
    rng = np.random.default_rng([seed, FLOOR_SEED, 1])
    if len(risky) > wanted // 4:
        risky = np.sort(rng.choice(risky, size=wanted // 4, replace=False))
    others = covered.copy()
    others[risky] = False
    # Twice the texels are drawn, the first that have points in both draws kept: the
    # scatter's footprint splats reach texels outside every UV triangle, which have none.
    cells = np.union1d(risky, pick_cells(others, 2 * (wanted - len(risky)), (seed + FLOOR_SEED) % 2**31))
    first = baker.sample_receivers(cells, 0)  # the gather's is a readback of its whole texel list: once
    draws = (first, baker.sample_receivers(cells, 1) if baker.FRESH_DRAWS else first)
    held = np.intersect1d(draws[0].texel, draws[1].texel)
    sample = FloorSample(held, draws, np.isin(held, risky), population)
    keep = sample.thinning(wanted, rng)
    return sample.part(np.arange(len(held)) if keep is None else keep)


def take_probe(plan: BakePlan, baker, count: int, snapshots: dict, cells: np.ndarray,
               sums: tuple[np.ndarray, np.ndarray]) -> FloorProbe:
    """The FloorProbe of a round from its snapshots (probe_steps, each a
    core/bake/probe_snapshot one) and its replicates' whole sums (replicate_sums_steps) at
    `cells` (sorted)."""
    split = replicate_sizes(count)[0]
    first, second = sorted(snapshots)
    half = first
    order = np.asarray(getattr(baker, "direction_order", np.arange(count)))
    values = np.stack([snapshots[step].at(cells) for step in (first, second)])
    channels = plan.estimator.channel_count
    full_values = np.stack([sums_value(plan.estimator, part.reshape(-1, channels)[cells]).astype(np.float64)
                            for part in sums])
    return FloorProbe(plan, half, np.stack([order[:half], order[split:split + half]]), values,
                      (order[:split], order[split:count]), full_values)


def refined_count(checked: int, probe: FloorProbe, directions: int) -> int:
    """How many of `checked` texels are checked again along all their round's directions:
    REFINED_SHARE of them, at most as many as the probe's rays buy again."""
    rays = min(FLOOR_RAYS_PER_DIRECTION * directions, FLOOR_RAYS_MAX)
    per_texel = sum(len(steps) for steps in probe.full_steps) // probe.plan.classes  # a texel's class's alone
    return int(min(math.ceil(checked * REFINED_SHARE), rays // max(per_texel, 1)))


def floor_steps(probe: FloorProbe, sample: FloorSample, directions: int, exact_cells: np.ndarray = (),
                cast: DistanceCast | None = None
                ) -> Generator[float, None, tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray] | None]:
    """(cells (n,), floor_a (n,), floor_b (n,), weight (n,)): each replicate's partial value
    minus the reference's along the same directions from the same points, at
    floor_texel_count(directions) of the sample's cells (a bake to an error draws its sample
    for its cap, and checks it for the directions it has baked; its texels at risk stay), and
    at the refined_count() of them with the largest floors its whole value minus the
    reference's along all its directions; weight: the share of the covered texels each stands
    for (FloorSample.weights). None where no cell is lit in both. exact_cells: cells the bake
    traced exactly after its probe (hao_addon/contact_repair.py): in the sample with a floor of
    0, not traced again. cast: how a replicate's exact rays are cast together (bakers.distance_cast_for;
    None: one at a time by the CPU's BVH). Yields progress in [0, 1]."""
    values, full_values = probe.values, probe.full_values
    wanted = floor_texel_count(directions)
    keep = sample.thinning(wanted, np.random.default_rng([directions, FLOOR_SEED]))
    if keep is not None:
        sample, values, full_values = sample.part(keep), values[:, keep], full_values[:, keep]
    cells, receivers = sample.cells, sample.receivers
    traced = np.isin(cells, exact_cells)
    untraced = np.flatnonzero(~traced)
    exact = np.array(values, np.float64)  # a cell traced exactly: its floor is 0
    exact[:, untraced] = yield from relay(
        _exact_steps(probe.plan, cells[untraced], tuple(r.subset(np.isin(r.texel, cells[untraced])) for r in receivers),
                     probe.steps, cast), lambda f: 0.5 * f)
    seen = np.isfinite(exact).all(axis=0) & np.isfinite(values).all(axis=0)
    if not seen.any():
        return None
    floor = np.clip(values, 0.0, 1.0) - np.clip(exact, 0.0, 1.0)
    floor[:, ~seen] = 0.0
    refined = np.argsort(-(floor ** 2).sum(axis=0), kind="stable")[:refined_count(int(seen.sum()), probe, directions)]
    refined = np.sort(refined[seen[refined] & ~traced[refined]])
    if len(refined):
        subset = tuple(r.subset(np.isin(r.texel, cells[refined])) for r in receivers)
        exact_all = yield from relay(_exact_steps(probe.plan, cells[refined], subset, probe.full_steps, cast),
                                     lambda f: 0.5 + 0.5 * f)
        again = np.isfinite(exact_all).all(axis=0) & np.isfinite(full_values[:, refined]).all(axis=0)
        floor[:, refined[again]] = (np.clip(full_values[:, refined[again]], 0.0, 1.0)
                                    - np.clip(exact_all[:, again], 0.0, 1.0))
    return cells[seen], floor[0, seen], floor[1, seen], sample.weights(seen)


def _exact_steps(plan: BakePlan, cells: np.ndarray, receivers: tuple[Receivers, Receivers],
                 steps: tuple[np.ndarray, np.ndarray] | np.ndarray, cast: DistanceCast | None
                 ) -> Generator[float, None, np.ndarray]:
    """(2, n) the reference's value at `cells` (n,) from each replicate's receivers along its
    `steps` (direction indices of plan's directions), NaN where unlit: exact rays, a
    replicate's cast together by `cast` where given. Yields progress."""
    from .core.bake.reference_baker import ReferenceBaker  # deferred: mathutils comes with bpy
    plan = plan.with_cells(cells)
    exact = np.full((2, len(cells)), np.nan)
    for k in range(2):
        baker = ReferenceBaker(plan, receivers[k], START_OFFSET_PIXELS * plan.pixel_size)
        try:
            baker.run_directions(np.asarray(steps[k]), cast)
            yield (k + 1) / 2
            numerator, w = plan.estimator.ratio(baker.accumulated_at(cells))
        finally:
            baker.free()
        lit = w > 0.0
        exact[k, lit] = numerator[lit] / w[lit]
    return exact
