# SPDX-License-Identifier: GPL-3.0-or-later
"""Direction sets over the unit sphere for the outside-in baker.

The baker renders the mesh from D directions. McGraw & Sowers draw them at random; a
spherical Fibonacci set is a low-discrepancy set with equal area per point, so the
quadrature error of the hemisphere integral shrinks faster than 1/sqrt(D). A seeded random
rotation removes the set's fixed alignment with the axes (a floor aligned with the poles
would otherwise see a degenerate pattern) while keeping bakes deterministic.
"""
from __future__ import annotations

import numpy as np

GOLDEN_ANGLE = np.pi * (3.0 - np.sqrt(5.0))


def fibonacci_sphere(count: int) -> np.ndarray:
    """Spherical Fibonacci points.

    Returns (count, 3) float64 unit vectors, each the centre of an equal-area cell.
    """
    if count < 1:
        raise ValueError(f"need at least one direction, got {count}")
    i = np.arange(count, dtype=np.float64)
    z = 1.0 - (2.0 * i + 1.0) / count
    r = np.sqrt(np.clip(1.0 - z * z, 0.0, 1.0))
    phi = i * GOLDEN_ANGLE
    return np.stack([r * np.cos(phi), r * np.sin(phi), z], axis=1)


def random_rotation(seed: int, stream: int = 0) -> np.ndarray:
    """A uniformly random rotation matrix (3, 3) float64 from a seed (QR of a Gaussian);
    streams > 0 give further independent rotations of the same seed."""
    rng = np.random.default_rng(seed if stream == 0 else [seed, stream])
    q, r = np.linalg.qr(rng.standard_normal((3, 3)))
    q *= np.sign(np.diag(r))
    if np.linalg.det(q) < 0.0:
        q[:, 0] = -q[:, 0]
    return q


# The baker's set is this many independently rotated Fibonacci sets (replicates), so that the
# bake can state its own error (core/bake/error_estimate.py). Each replicate is an unbiased
# estimate of the integral over the random rotation; two are the fewest that show their
# spread, and every further one costs accuracy: a union of k independent sets of D / k is
# noisier than one set of D (measured on the smooth rocker arm and Spot against Cycles:
# 1.08-1.21x the RMSE for two, 1.13-1.50x for four, at 64 to 1024 directions).
REPLICATES = 2


def replicate_sizes(count: int) -> list[int]:
    """Directions of each replicate, in order (the first ones one larger when count is odd;
    a single direction is a single replicate)."""
    k = min(REPLICATES, count)
    return [count // k + (r < count % k) for r in range(k)]


# A GPU bake's floor probe (hao_addon/floor_check.py): each replicate's first probe_half()
# directions, a random subset of it, are baked first, so that its partial sums after them are
# a map of its own: an eighth of the bake's directions, at least PROBE_MIN and at most
# PROBE_MAX per replicate. Few directions per texel, many texels: the check's error comes
# mostly from the few texels that hold the floor's tail (the bunny at 128^2, flat, 4096
# directions: half its square in 3-11 of 6501 texels), which only more texels catch; the
# probe's own direction noise cancels in the product of the two replicates (a ray budget
# spread over 256 directions and all texels stated 0.0051 where 1024 directions at 1024
# texels stated 0.0042, against 0.0054 measured).
PROBE_MIN = 64
PROBE_MAX = 256


def probe_half(count: int) -> int:
    """Directions per replicate of the floor probe of a bake of `count` directions."""
    return min(replicate_sizes(count)[-1], int(np.clip(count // 8, PROBE_MIN, PROBE_MAX)))


def probe_first(count: int, half: int) -> tuple[np.ndarray, np.ndarray]:
    """(probe, rest): sorted indices into a replicate of `count` directions, a probe of
    min(half, count) of them drawn at random (seeded by count and half), and the others.

    Why at random: under the replicate's random rotation any subset is unbiased, but the
    probe's value at a texel is a ratio (its directions' weighted visibility over their
    weights), and a structured subset's weight sum swings with the rotation. Every 4th point of
    a spherical Fibonacci set steps its azimuth by 4/golden ratio, almost half a turn: two
    meridians' worth of points, whose ratio overstated the floor by 1.7x (Spot at 128^2). A
    random subset's weight sum varies as little as any random set's."""
    half = min(half, count)
    probe = np.sort(np.random.default_rng([count, half]).permutation(count)[:half])
    rest = np.setdiff1d(np.arange(count), probe)
    return probe, rest


def probe_order(count: int) -> list[np.ndarray]:
    """Each replicate's parts in baking order, as indices into the bake's `count` directions:
    its floor probe (probe_first, probe_half(count) of them) and then the rest."""
    starts = np.cumsum([0, *replicate_sizes(count)])
    half = probe_half(count)
    return [a + part for a, b in zip(starts[:-1], starts[1:]) for part in probe_first(int(b - a), half)]


# The azimuth step, in turns, of the lattice whose points every 4th (one texel class of four)
# are a spherical Fibonacci set: (golden ratio - 1 + j) / 4 makes each class's step the golden
# one, and j sets the union's. Under a ball resting on a floor at 1024^2, 256 directions a
# texel, the shadow's RMSE after an 8 x 8 box filter for j = 0..3: 0.0030, 0.0021, 0.0017,
# 0.0022 (each texel's own RMSE 0.0070 for all; four independently rotated sets: 0.0026; one set
# for all texels: 0.0052). A numpy model of the gather, bench/structured_error_bench.py.
CLASS_LATTICE_STEP = {4: ((np.sqrt(5.0) - 1.0) / 2.0 + 2.0) / 4.0}


def lattice_sphere(count: int, step: float) -> np.ndarray:
    """(count, 3) points z_i = 1 - (2 i + 1) / count, azimuth i * step turns: equal area per
    point, as fibonacci_sphere, whose step is the golden one."""
    i = np.arange(count, dtype=np.float64)
    z = 1.0 - (2.0 * i + 1.0) / count
    r = np.sqrt(np.clip(1.0 - z * z, 0.0, 1.0))
    phi = 2.0 * np.pi * np.mod(i * step, 1.0)
    return np.stack([r * np.cos(phi), r * np.sin(phi), z], axis=1)


def class_directions(count: int, seed: int, classes: int) -> tuple[np.ndarray, np.ndarray]:
    """The baker's direction set for `count` directions per texel and `classes` texel classes
    (core/bake/interleave.py; 1 or a key of CLASS_LATTICE_STEP): REPLICATES lattices
    (lattice_sphere) of classes x count / REPLICATES points, each with its own random rotation
    (bake_directions' for one class), every classes-th point of a lattice serving one class:
    each class gets a spherical Fibonacci set of its own, and what a few neighbouring texels
    see together is the whole lattice. In the second replicate the classes' points are shifted
    by classes / 2, so that with an odd count every class sees count directions.

    Returns ((classes * count, 3) float64 unit vectors pointing from the surface towards the
    sky, in replicate order (replicate_sizes(classes * count)), and (classes * count,) int the
    class each serves)."""
    if classes == 1:
        return bake_directions(count, seed), np.zeros(count, np.int64)
    if classes not in CLASS_LATTICE_STEP or count < 2:
        raise ValueError(f"texel classes are 1 or {sorted(CLASS_LATTICE_STEP)} with 2 directions or more, "
                         f"got {classes} and {count}")
    sizes = replicate_sizes(classes * count)
    points = [lattice_sphere(n, CLASS_LATTICE_STEP[classes]) @ random_rotation(seed, r).T for r, n in enumerate(sizes)]
    served = [(np.arange(n) + r * (classes // 2)) % classes for r, n in enumerate(sizes)]
    return np.concatenate(points), np.concatenate(served)


def bake_directions(count: int, seed: int = 0) -> np.ndarray:
    """The baker's direction set without texel classes: REPLICATES spherical Fibonacci sets,
    each with its own random rotation (replicate_sizes, one after the other).

    Returns (count, 3) float64 unit vectors pointing from the surface towards the sky.
    """
    return np.concatenate([fibonacci_sphere(n) @ random_rotation(seed, r).T
                           for r, n in enumerate(replicate_sizes(count))])


def stratified_cosine_hemisphere(count: int, rng: np.random.Generator) -> np.ndarray:
    """Cosine-weighted directions about +z, stratified on the unit disk.

    A jittered sqrt(count) x sqrt(count) grid on the square is mapped to the disk by the
    concentric (Shirley-Chiu) map and lifted to the hemisphere (Malley's method), so the
    pdf is cos(theta)/pi and the estimator of the cosine-weighted visibility is a plain mean.
    Returns (n, 3) float64 with n = floor(sqrt(count))**2.
    """
    side = max(1, int(np.sqrt(count)))
    gy, gx = np.meshgrid(np.arange(side), np.arange(side), indexing="ij")
    u = (gx.ravel() + rng.random(side * side)) / side * 2.0 - 1.0
    v = (gy.ravel() + rng.random(side * side)) / side * 2.0 - 1.0
    # Concentric map: avoids the clumping of the polar map at the centre.
    use_u = np.abs(u) > np.abs(v)
    r = np.where(use_u, u, v)
    safe_u = np.where(u == 0.0, 1.0, u)
    safe_v = np.where(v == 0.0, 1.0, v)
    theta = np.where(use_u, (np.pi / 4.0) * (v / safe_u), (np.pi / 2.0) - (np.pi / 4.0) * (u / safe_v))
    x = r * np.cos(theta)
    y = r * np.sin(theta)
    z = np.sqrt(np.clip(1.0 - x * x - y * y, 0.0, 1.0))
    return np.stack([x, y, z], axis=1)


def malley_quadrature(samples: int) -> np.ndarray:
    """(samples^2, 3) local directions (z up) of a samples x samples midpoint rule on Malley's
    disk: equal-weight, cosine-distributed quadrature nodes of the hemisphere (their mean of
    any f approximates (1/pi) int f cos d omega)."""
    k = (np.arange(samples) + 0.5) / samples
    r = np.sqrt(k)[:, None]
    phi = 2.0 * np.pi * k[None, :]
    shape = (samples, samples)
    return np.stack([np.broadcast_to(r * np.cos(phi), shape), np.broadcast_to(r * np.sin(phi), shape),
                     np.broadcast_to(np.sqrt(1.0 - r * r), shape)], -1).reshape(-1, 3)


def frame_from_normal(n: np.ndarray) -> np.ndarray:
    """Orthonormal frames (m, 3, 3) whose third row is the unit normal n (m, 3).

    Uses the branch-free construction of Duff et al. 2017 (no singularity at n = -z).
    """
    n = np.asarray(n, dtype=np.float64)
    sign = np.where(n[:, 2] >= 0.0, 1.0, -1.0)
    a = -1.0 / (sign + n[:, 2])
    b = n[:, 0] * n[:, 1] * a
    t = np.stack([1.0 + sign * n[:, 0] ** 2 * a, sign * b, -sign * n[:, 0]], axis=1)
    s = np.stack([b, sign + n[:, 1] ** 2 * a, -n[:, 1]], axis=1)
    return np.stack([t, s, n], axis=1)
