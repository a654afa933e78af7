# SPDX-License-Identifier: GPL-3.0-or-later
"""A bake's statistical error, stated by the bake itself (pure numpy).

The D directions are REPLICATES (two) spherical Fibonacci sets, each with its own independent,
uniformly random rotation (core/directions.py), accumulated apart. Why that is honest:

- Over the random rotation a replicate's value at a texel, x_A or x_B, is an unbiased
  estimate of the converged value mu (the same estimator with infinitely many directions): a
  uniformly rotated point set samples every direction with equal probability.
- Their errors e_A = x_A - mu and e_B = x_B - mu are independent (independent rotations) and
  identically distributed (the same point set).
- The map is their mean, with error (e_A + e_B) / 2. The *twin* (x_A - x_B) / 2 = (e_A - e_B) / 2
  has the same variance, and exactly the same distribution when e_B is symmetric (e_A - e_B
  is then e_A + e_B in law).

So each texel's twin is a draw from the distribution of that texel's error: the twins' RMS over
the covered texels estimates the map's RMSE, their 99th percentile its p99, with nothing assumed
about how fast the error falls with D. The structured error of a shared direction set (every
texel sees the same directions, so neighbours err alike: bands rather than grain) is in it,
because each replicate carries its own. Two interleaved halves of one Fibonacci set would not
do: their errors are negatively correlated (the whole set is better than either half), and the
halves' spread overstated the error (by about 40 % at 256 directions on the rocker arm).

What the twins do not show: the error every direction count shares (shadow-map resolution,
texel sampling), which more directions never remove. A GPU bake therefore also measures that
part, its visibility floor (hao_addon/floor_check.py): at sampled texels, the CPU reference's
exact rays along the bake's own directions, against the map. With the same directions the
difference holds no direction noise, only what the visibility test gets wrong, and
with_floor() adds it to the twins' estimate: the stated error is the whole error.
A single texel's twin is one draw, so the error image is the twins' RMS over each texel's
neighbourhood (local_rms), and per-texel convergence is judged from that (converged).
"""
from __future__ import annotations

import math
from dataclasses import asdict, dataclass, replace

import numpy as np

# The 99th percentile of |e| for a normal e is 2.576 sigma: a texel whose local RMS error times
# this is below E has converged for a p99 bound of E.
Z99 = 2.5758293035489
# How the twins' p99 falls with directions: (up to D, as D^-rate). Measured on the smooth rocker
# arm and Spot (bench/error_bench.py, 64 to 16384 directions): 0.755 from 64 to 1024 on both,
# then 0.70, 0.64, 0.60 on the rocker arm (0.70, 0.63, 0.61, 0.53 on Spot) per doubling: a
# Fibonacci set's advantage over random directions shrinks as its cells get smaller than the
# features they resolve. A prediction only: the bake stops on its measured estimate.
RATE_PROFILE = ((1024.0, 0.75), (math.inf, 0.62))
PILOT_DIRECTIONS = 64    # the first round of a bake to an error
MIN_ROUND = 32           # no round smaller (a round is a whole bake: its set-up is paid again)
OVERSHOOT = 1.1          # a round aims this much past the predicted count, to end in one more
NEIGHBOURHOOD = 2        # local_rms: (2 r + 1)^2 texels
CONVERGED_MARGIN = 2.0   # converged: a texel's estimated p99 at most half the target


@dataclass(frozen=True)
class ErrorEstimate:
    """A map's estimated statistical error over its covered texels: rmse and p99 of |error|,
    from the twins; directions: how many the map used; capped: a bake to an error stopped at
    its cap before reaching it."""

    rmse: float
    p99: float
    directions: int
    capped: bool = False
    # The visibility floor in it (with_floor): its RMSE and p99 at floor_texels sampled texels
    # (0 texels: not measured, as for the reference, whose visibility is exact).
    floor_rmse: float = 0.0
    floor_p99: float = 0.0
    floor_texels: int = 0
    # Why a GPU method's floor is not measured (abilities.floor_unchecked; every GPU baker's is
    # measured today), '' otherwise: a report never passes off the twins' part as the whole.
    floor_unmeasured: str = ""

    def as_dict(self) -> dict:
        return asdict(self)

    def text(self) -> str:
        """'error ~0.0042 RMSE, 0.011 p99 (256 directions)' for summary lines and reports."""
        floor = (f"; visibility floor {self.floor_rmse:.2g} RMSE" if self.floor_texels else
                 "; visibility floor not measured" if self.floor_unmeasured else "")
        return (f"error ~{self.rmse:.2g} RMSE, {self.p99:.2g} p99 ({self.directions} directions"
                f"{', capped' if self.capped else ''}{floor})")


def replicate_twin(numerator_a: np.ndarray, weight_a: np.ndarray, numerator_b: np.ndarray, weight_b: np.ndarray
                   ) -> np.ndarray:
    """(...) float32 twins (x_A - x_B) / 2 from the two replicates' sums (each (...)); 0 where
    either replicate has no weight (no estimate to compare)."""
    both = (weight_a > 0.0) & (weight_b > 0.0)
    x_a = np.divide(numerator_a, weight_a, out=np.zeros_like(numerator_a, dtype=np.float64), where=both)
    x_b = np.divide(numerator_b, weight_b, out=np.zeros_like(numerator_b, dtype=np.float64), where=both)
    return (0.5 * (np.clip(x_a, 0.0, 1.0) - np.clip(x_b, 0.0, 1.0))).astype(np.float32)


def estimate(twin: np.ndarray, covered: np.ndarray, directions: int, capped: bool = False) -> ErrorEstimate | None:
    """The map's ErrorEstimate from its twins (...) over covered (...) bool; None without
    covered texels or with a single replicate (one direction)."""
    values = np.abs(twin[covered]).astype(np.float64)
    if values.size == 0 or directions < 2:
        return None
    return ErrorEstimate(float(np.sqrt((values * values).mean())), float(np.percentile(values, 99)), int(directions),
                         capped)


# with_floor's p99: each sampled texel's error drawn at these standard normal quantiles.
FLOOR_QUANTILES = 64


def with_floor(error: ErrorEstimate, floor_a: np.ndarray, floor_b: np.ndarray, sigma: np.ndarray,
               weight: np.ndarray | None = None) -> ErrorEstimate:
    """The whole error: `error` (the twins') with the visibility floor measured at sampled
    texels. floor_a, floor_b: (n,) each replicate's value there minus the exact value along its
    own directions (hao_addon/floor_check.py); sigma: (n,) the twins' local RMS there (the
    direction noise each texel has on top); weight: (n,) how many covered texels each stands
    for (a stratified sample: floor_check.FloorSample), or None for a plain random sample.

    The floor proper is the part of floor_a and floor_b that their independent rotations share:
    its mean square is the mean of floor_a * floor_b (the parts that change with the rotation
    are in the twins already, and counting them again overstated Spot's error at 256
    directions by 1.2x). RMSE: the floor and the noise are independent, so their squares add.
    p99: each texel's error is its floor (floor_shape, scaled to the floor proper's RMS) plus
    its noise at FLOOR_QUANTILES normal quantiles; the noise is scaled so that alone it gives
    the twins' p99 (over every texel). Scaling the p99 with the floor by that ratio instead
    scaled the floor too: where the floor is most of the error the sampled texels' noise set
    it, and the scatter on smooth fandisk stated a p99 of 0.061 under a floor whose own p99
    was 0.072."""
    floor_a, floor_b = np.asarray(floor_a, np.float64), np.asarray(floor_b, np.float64)
    if floor_a.size == 0:
        return error
    weight = np.ones(floor_a.size) if weight is None else np.asarray(weight, np.float64)
    square = max(float(np.average(floor_a * floor_b, weights=weight)), 0.0)
    floor = floor_shape(floor_a, floor_b)
    mean_square = float(np.average(floor ** 2, weights=weight))
    floor = floor * (np.sqrt(square / mean_square) if mean_square > 0.0 else 0.0)
    sigma = np.asarray(sigma, np.float64)
    z = _normal_quantiles(FLOOR_QUANTILES)
    spread = np.repeat(weight, z.size)  # each texel's FLOOR_QUANTILES draws weigh as it does
    without = weighted_percentile(np.abs(sigma[:, None] * z[None]).ravel(), spread, 99)
    noise = sigma * (error.p99 / without if without > 0.0 else 1.0)  # the twins' p99 calibrates the noise
    p99 = weighted_percentile(np.abs(floor[:, None] + noise[:, None] * z[None]).ravel(), spread, 99)
    return replace(error, rmse=float(np.sqrt(error.rmse ** 2 + square)), p99=float(max(p99, error.p99)),
                   floor_rmse=float(np.sqrt(square)), floor_p99=weighted_percentile(np.abs(floor), weight, 99),
                   floor_texels=int(floor.size))


def weighted_percentile(values: np.ndarray, weight: np.ndarray, q: float) -> float:
    """The q-th percentile of (n,) values each weighing weight (n,): numpy's linear one where
    all weigh alike (its interpolation between the order statistics at rank q/100 (n - 1))."""
    order = np.argsort(values, kind="stable")
    v, w = values[order], weight[order]
    rank = np.cumsum(w) - 0.5 * w  # each value at the middle of its weight
    rank = (rank - rank[0]) / max(rank[-1] - rank[0], 1e-300) * (len(v) - 1)
    return float(np.interp(q / 100.0 * (len(v) - 1), rank, v))


def floor_shape(floor_a: np.ndarray, floor_b: np.ndarray) -> np.ndarray:
    """(n,) each sampled texel's floor as with_floor spreads it, before scaling: the geometric
    mean of its two replicates' floors, signed as their sum (0 where they differ in sign).

    Why not their mean: the floor is heavy-tailed (the rocker arm at 128^2, flat: one texel of
    6949, the shadow maps missing a nearby occluder there, holds a fifth of its square), while a
    probe's part that changes with the rotation is not, and at few probe directions it is the
    larger (RMS 0.008 against a floor of 0.0023 at 256 per replicate). Their mean is mostly that
    part, so scaled to the floor proper's RMS it took the part's shape, and the tail texels
    shrank with the rest: the p99 stated 0.72x the measured one at 16384 directions. The
    product floor_a * floor_b is each texel's unbiased estimate of its floor's square (the
    parts that change with the rotation are independent); its root keeps a tail texel whole
    (both replicates see it) and gives a texel with no floor less than the mean does."""
    product = floor_a * floor_b
    return np.sign(floor_a + floor_b) * np.sqrt(np.maximum(product, 0.0))


def _normal_quantiles(count: int) -> np.ndarray:
    """(count,) the standard normal's quantiles at (k + 1/2) / count, by bisection of math.erf
    (numpy has no inverse of it)."""
    targets = (np.arange(count) + 0.5) / count
    out = np.empty(count)
    for k, t in enumerate(targets):
        lo, hi = -10.0, 10.0
        for _ in range(80):
            mid = 0.5 * (lo + hi)
            lo, hi = (mid, hi) if 0.5 * (1.0 + math.erf(mid / math.sqrt(2.0))) < t else (lo, mid)
        out[k] = 0.5 * (lo + hi)
    return out


def _box_sum(values: np.ndarray, radius: int) -> np.ndarray:
    """Sum over each (2 radius + 1)^2 box of a (H, W) array, zero outside."""
    padded = np.pad(values, ((radius + 1, radius), (radius + 1, radius)))  # a leading zero row and column
    c = padded.cumsum(0).cumsum(1)
    k = 2 * radius + 1
    return c[k:, k:] - c[:-k, k:] - c[k:, :-k] + c[:-k, :-k]


def local_rms(twin: np.ndarray, covered: np.ndarray, radius: int = NEIGHBOURHOOD) -> np.ndarray:
    """(H, W) float32: the RMS of the covered texels' twins in each texel's neighbourhood
    (a per-texel standard error from (2 radius + 1)^2 draws); 0 where no covered neighbour.
    A layout with a leading tile axis is taken tile by tile."""
    if twin.ndim == 3:
        return np.stack([local_rms(t, c, radius) for t, c in zip(twin, covered)])
    if twin.ndim != 2:  # elements (colour attributes) have no neighbourhood: their own |twin|
        return np.abs(twin).astype(np.float32)
    square = np.where(covered, twin.astype(np.float64) ** 2, 0.0)
    count = _box_sum(covered.astype(np.float64), radius)
    mean = np.divide(_box_sum(square, radius), count, out=np.zeros_like(square), where=count > 0)
    return np.sqrt(np.maximum(mean, 0.0)).astype(np.float32)  # box sums by differences: -1e-20 is 0


def converged(twin: np.ndarray, covered: np.ndarray, max_error: float) -> np.ndarray:
    """(...) bool: covered texels whose error is within max_error at the 99th percentile with
    room to spare: Z99 x their neighbourhood's RMS twin (local_rms) at most max_error /
    CONVERGED_MARGIN.

    The margin is there because the choice is made from the same twins the bake later reports:
    a texel chosen for a small neighbourhood RMS may have drawn small twins by chance, and it
    gets no further round to show otherwise. Without the margin, Spot at 'draft' reported a
    p99 of 0.0098 where 0.012 was measured; choosing by the map's value instead (independent
    of the twin) selects on the error itself (0.013 measured). Even with it the rocker arm at
    half an 8-bit step reported 0.0019 where 0.0025 was measured, so bakes do not leave these
    texels out (hao_addon.bake.SKIP_CONVERGED); they report the share they could."""
    return covered & (Z99 * CONVERGED_MARGIN * local_rms(twin, covered) <= max_error)


def directions_for(p99: float, directions: float, max_error: float) -> float:
    """The directions at which a p99 of `p99` at `directions` falls to max_error along
    RATE_PROFILE (each stretch at its own rate)."""
    for end, rate in RATE_PROFILE:
        if directions >= end:
            continue
        reach = directions * (p99 / max_error) ** (1.0 / rate)
        if reach <= end:
            return reach
        p99 *= (end / directions) ** -rate
        directions = end
    return directions


def next_round(history: list[tuple[int, float]], max_error: float, cap: int) -> int:
    """Directions of the next round of a bake to a p99 of max_error, from (directions so far,
    p99 then) after each round: the count RATE_PROFILE predicts from the last, OVERSHOOT past
    it, at least MIN_ROUND, at most what the cap leaves; 0 when done or capped."""
    total, p99 = history[-1]
    if p99 <= max_error or total >= cap:
        return 0
    needed = directions_for(p99, total, max_error) * OVERSHOOT
    return int(min(cap - total, max(MIN_ROUND, math.ceil(needed) - total)))
