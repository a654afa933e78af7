# SPDX-License-Identifier: GPL-3.0-or-later
"""The bound an incremental re-bake keeps texels by (core/bake/change_bound.py) against the
exact occlusion of a sphere: a sphere of radius r wholly above a receiver's horizon, its
centre D away at angle phi from the normal, occludes (r / D)^2 cos(phi) of its cosine-weighted
hemisphere (the sphere's form factor); uniformly weighted, 1 - sqrt(1 - (r / D)^2) at most."""
from __future__ import annotations

import numpy as np
import pytest

from hao_addon.core.bake import change_bound as cb

pytestmark = pytest.mark.release_independent


def sphere_form_factor(points: np.ndarray, centre: np.ndarray, r: float) -> np.ndarray:
    """Exact cosine-weighted occlusion of a sphere above the plane z = 0 (normal +z) at points
    whose horizon it lies wholly above (centre height > r)."""
    d = centre - points
    dist = np.linalg.norm(d, axis=1)
    return (r / dist) ** 2 * d[:, 2] / dist


def test_the_bound_holds_and_is_reached_below_a_sphere():
    """On a plane under a sphere (r 0.3 at heights 0.5 to 3): the bound is at least the exact
    occlusion everywhere, and equal to it directly below; with the exponent 2.5 instead of 2,
    or the bound halved, it fails there."""
    rng = np.random.default_rng(3)
    points = np.column_stack([rng.uniform(-4, 4, 5000), rng.uniform(-4, 4, 5000), np.zeros(5000)])
    for height in (0.5, 1.0, 3.0):
        centre, r = np.array([0.2, -0.1, height]), 0.3
        exact = sphere_form_factor(points, centre, r)
        bound = cb.change_bound(points, np.array([[*centre, r]]))
        assert np.all(bound >= exact - 1e-12)
        below = np.array([[0.2, -0.1, 0.0]])
        assert cb.change_bound(below, np.array([[*centre, r]]))[0] == pytest.approx(
            sphere_form_factor(below, centre, r)[0], rel=1e-12)
    # The mistakes the test is for: a weaker exponent, or a bound too small by half.
    dist = np.linalg.norm(points - np.array([0.2, -0.1, 0.5]), axis=1)
    exact = sphere_form_factor(points, np.array([0.2, -0.1, 0.5]), 0.3)
    assert np.any((0.3 / dist) ** 2.5 < exact) and np.any(0.5 * (0.3 / dist) ** 2 < exact)


def test_uniform_weighting_spread_max_distance_and_inside():
    """Uniform weighting: the cone's solid angle share 1 - cos t; a spread of 45 degrees
    normalizes by its smaller cone; beyond the max distance nothing; inside the sphere 1;
    two spheres add, capped at 1."""
    p = np.zeros((1, 3))
    s = np.array([[0.0, 0.0, 2.0, 0.5]])
    sin_t = 0.25
    assert cb.change_bound(p, s, "uniform")[0] == pytest.approx(1 - np.sqrt(1 - sin_t ** 2))
    assert cb.change_bound(p, s, "cosine", spread_angle=45.0)[0] == pytest.approx(sin_t ** 2 / 0.5)
    assert cb.change_bound(p, s, "cosine", max_distance=1.4)[0] == 0.0
    assert cb.change_bound(p, s, "cosine", max_distance=1.6)[0] == pytest.approx(sin_t ** 2)
    assert cb.change_bound(np.array([[0.0, 0.0, 1.8]]), s)[0] == 1.0
    assert cb.change_bound(p, np.concatenate([s, s]))[0] == pytest.approx(2 * sin_t ** 2)
    assert cb.change_bound(p, np.repeat(np.array([[0.0, 0.0, 1.0, 0.9]]), 3, axis=0))[0] == 1.0
    # A cell's bound is its receivers' largest.
    np.testing.assert_array_equal(cb.cell_bound(np.array([0.1, 0.3, 0.2]), np.array([2, 2, 0]), 4),
                                  [0.2, 0.0, 0.3, 0.0])


def test_uniform_exact_share_of_a_cone_matches_sampled_directions():
    """The uniform share 1 - cos t is the fraction of hemisphere directions inside a cone along
    the normal (10^6 uniform directions, within their noise)."""
    rng = np.random.default_rng(0)
    w = rng.normal(size=(1_000_000, 3))
    w /= np.linalg.norm(w, axis=1, keepdims=True)
    w = w[w[:, 2] > 0]
    t = np.radians(20.0)
    inside = (w[:, 2] >= np.cos(t)).mean()
    assert cb.cone_share(np.array([np.sin(t)]), "uniform")[0] == pytest.approx(inside, abs=5e-3 * 3)
    # Cosine weighting: the weight share inside the cone is sin^2 t.
    share = (w[:, 2] * (w[:, 2] >= np.cos(t))).sum() / w[:, 2].sum()
    assert cb.cone_share(np.array([np.sin(t)]), "cosine")[0] == pytest.approx(share, abs=3e-3)
