# SPDX-License-Identifier: GPL-3.0-or-later
"""A bake checked from outside (--verify N): N random covered texels re-estimated by the CPU
reference with many directions, and the map's RMSE, p99 and bias against it with 95 %
intervals (pure numpy; the tracing is hao_addon.verify).

What the reference shares with the bake it checks, and so cannot see: the surface points (texel
centres or their sub-texel samples, or the projected high-poly points), their shading normals
and the estimator (weights, terminator rule, max distance). What it does not share: how
visibility is found (rays against the triangles, not depth maps or splats) and the directions
(its own set, VERIFY_DIRECTIONS of them). So it measures the bake's statistical error and the
systematic error of its visibility test together, which the bake's own estimate
(core/bake/error_estimate.py) cannot: that one sees only what more directions remove.

The reference's own noise (from its two replicates, as every bake's) is taken out of the RMSE;
the intervals are percentile bootstraps over the sampled texels (seeded: the same report on
every run).
"""
from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np

VERIFY_DIRECTIONS = 4096
VERIFY_SEED = 104729   # the reference's directions: a seed no bake's rounds use
BOOTSTRAP = 2000
SHARES = ("the same surface points, shading normals and estimator as the bake; its own directions, and rays "
          "against the triangles instead of the bake's visibility test")


@dataclass(frozen=True)
class Verification:
    """The map against the reference at `texels` sampled texels: each measure as
    (95 % low, value, 95 % high); reference_noise: the reference's own RMSE (taken out of rmse)."""

    texels: int
    directions: int
    rmse: tuple[float, float, float]
    p99: tuple[float, float, float]
    bias: tuple[float, float, float]
    reference_noise: float
    shares: str = SHARES

    def as_dict(self) -> dict:
        return {k: list(v) if isinstance(v, tuple) else v for k, v in asdict(self).items()}

    def misses(self, max_error: float) -> bool:
        """The interval says the map's p99 error is above max_error (its low end is)."""
        return self.p99[0] > max_error

    def text(self) -> str:
        def fmt(name, v):
            return f"{name} {v[1]:.2g} [{v[0]:.2g}, {v[2]:.2g}]"
        return (f"verified at {self.texels} texels against the reference ({self.directions} directions): "
                f"{fmt('RMSE', self.rmse)}, {fmt('p99', self.p99)}, {fmt('bias', self.bias)}")


def pick_cells(covered: np.ndarray, count: int, seed: int) -> np.ndarray:
    """(min(count, covered), ) sorted flat indices of covered cells, drawn without repeats."""
    flat = np.flatnonzero(covered.ravel())
    rng = np.random.default_rng([seed, VERIFY_SEED])
    return np.sort(rng.choice(flat, size=min(count, len(flat)), replace=False))


def verification(values: np.ndarray, reference: np.ndarray, reference_twin: np.ndarray, directions: int,
                 seed: int) -> Verification:
    """values, reference, reference_twin: (n,) the map, the reference and the reference's twin
    at the sampled cells."""
    d = values.astype(np.float64) - reference
    noise = reference_twin.astype(np.float64) ** 2
    n = len(d)
    rng = np.random.default_rng([seed, VERIFY_SEED, 1])
    picks = rng.integers(0, n, size=(BOOTSTRAP, n))

    def rmse(rows):
        return np.sqrt(np.maximum((d[rows] ** 2).mean(-1) - noise[rows].mean(-1), 0.0))

    def p99(rows):
        return np.percentile(np.abs(d[rows]), 99, axis=-1)

    def bias(rows):
        return d[rows].mean(-1)

    everything = np.arange(n)

    def measured(f):
        low, high = np.percentile(f(picks), [2.5, 97.5])
        return float(low), float(f(everything)), float(high)

    return Verification(n, directions, measured(rmse), measured(p99), measured(bias),
                        float(np.sqrt(noise.mean())))
