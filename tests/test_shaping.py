# SPDX-License-Identifier: GPL-3.0-or-later
"""AO shaping (issue 30 item 4): a spread angle (a cone about the normal instead of the
hemisphere) and a min occluder distance (nearer hits passed by), on every baker, against
analytic scenes: a floor under an infinite ceiling at height H.

Cosine-weighted over the cone cos(theta) >= c, the share of directions with cos(theta) < x
is (x^2 - c^2) / (1 - c^2). A ray at theta meets the ceiling after H / cos(theta):
- within a max distance d it occludes when cos(theta) > H / d: accessibility
  ((H/d)^2 - c^2) / (1 - c^2);
- with a min distance m it is passed by when cos(theta) > H / m (unlimited distance: the
  other rays are occluded): accessibility 1 - (H/m)^2 for the hemisphere."""
from __future__ import annotations

import math

import numpy as np
import pytest

from bake_helpers import assert_within_sample_tolerance, error_stats
from hao_addon.bake import bake
from hao_addon.core import scenes
from hao_addon.core.bake.abilities import bakers_with
from hao_addon.core.bake.settings import BakeSettings

DIRS = 256
H = 0.5


def floor():
    return scenes.grid_plane(4.0, 4, name="floor")


def ceiling(z: float = H):
    return scenes.grid_plane(200.0, 4, z=z, name="ceiling")


def check(occluders: list, truth: float, method: str, **kw) -> None:
    """Every texel of the floor has one normal, so they all share one quadrature of the
    direction set: its error against the analytic value is a single draw, within sigma / 2
    (bake_helpers' RMSE bound) for the reference; a GPU pass, which uses the same directions,
    is held to the sample tolerance against the reference's value."""
    from bake_helpers import sigma
    reference = bake(floor(), occluders, settings("reference", **kw), use_cache=False)
    value = float(reference.ao[reference.covered].mean())
    assert abs(value - truth) <= sigma(DIRS) / 2, (value, truth)
    if method != "reference":
        res = bake(floor(), occluders, settings(method, **kw), use_cache=False)
        assert_within_sample_tolerance(error_stats(res.ao, np.full(res.ao.shape, value), res.covered), DIRS, method)


def settings(method: str, **kw) -> BakeSettings:
    return BakeSettings(size=16 if method == "reference" else 64, directions=DIRS, method=method, margin=0, **kw)


@pytest.mark.parametrize("method", bakers_with("spread", "max-distance"))
def test_spread_angle_counts_the_cone_only(gpu_context, method):
    d, spread = 1.25, 75.0
    c = math.cos(math.radians(spread))
    check([ceiling()], ((H / d) ** 2 - c * c) / (1.0 - c * c), method, max_distance=d, spread_angle=spread)  # 0.0997
    check([ceiling()], (H / d) ** 2, method, max_distance=d)  # the hemisphere's: 0.16


@pytest.mark.parametrize("method", bakers_with("min-distance"))
def test_min_distance_passes_nearer_occluders_by(gpu_context, method):
    m = 1.0
    check([ceiling()], 1.0 - (H / m) ** 2, method, min_distance=m)  # 0.75
    # A second ceiling beyond: the rays that pass the first are stopped there.
    both = bake(floor(), [ceiling(), ceiling(3.0)], settings(method, min_distance=m), use_cache=False)
    assert both.ao[both.covered].max() < 0.02


def test_the_defaults_shape_nothing(gpu_context):
    """Spread 90 and min distance 0 are today's bake, bit for bit (no shader variant)."""
    plain = bake(floor(), [ceiling()], BakeSettings(size=32, directions=32, method="gather", max_distance=1.0),
                 use_cache=False)
    same = bake(floor(), [ceiling()], BakeSettings(size=32, directions=32, method="gather", max_distance=1.0,
                                                   spread_angle=90.0, min_distance=0.0), use_cache=False)
    np.testing.assert_array_equal(plain.ao, same.ao)
