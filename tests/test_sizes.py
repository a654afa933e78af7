# SPDX-License-Identifier: GPL-3.0-or-later
"""Every option at every size: light views larger than a GPU's 3D texture side (2048 on
Mesa's OpenGL) bake a max distance's depth lists too, on the backend this Blender runs."""
from __future__ import annotations

import numpy as np
import pytest

from hao_addon.bake import bake
from hao_addon.core import scenes
from hao_addon.core.bake.abilities import bakers_with
from hao_addon.core.bake.settings import BakeSettings

R, REACH = 0.5, 0.5


@pytest.mark.parametrize("method", bakers_with("max-distance", gpu_only=True))
def test_max_distance_bakes_views_wider_than_a_3d_texture(gpu_context, method):
    """A floor under a ball at 2048^2 (light views of about 2.8k pixels a side: before the
    lists were 2D array textures, Blender refused their 3D texture on OpenGL, an internal
    error) equals the same bake at 1024^2 (views of 1.4k), 2 x 2 texels to one: both take the
    same directions, so what differs is resolution alone."""
    floor, ball = scenes.grid_plane(2.0, 4), scenes.uv_sphere(R, (0.0, 0.0, R), 48, 24)
    settings = dict(directions=8, method=method, max_distance=REACH, falloff="wendland", margin=0)
    large = bake(floor, [ball], BakeSettings(size=2048, **settings), use_cache=False)
    small = bake(floor, [ball], BakeSettings(size=1024, **settings), use_cache=False)
    side = {name: (res.stats["view_pixels"] / res.stats["directions_done"]) ** 0.5 for name, res in (("large", large), ("small", small))}
    assert side["large"] > 2048 >= side["small"], side
    pooled = large.ao.reshape(1024, 2, 1024, 2).mean(axis=(1, 3))
    both = small.covered & large.covered.reshape(1024, 2, 1024, 2).all(axis=(1, 3))
    diff = np.abs(pooled - small.ao)[both]
    assert both.sum() > 0.9 * 1024**2 and diff.mean() < 0.005 and np.percentile(diff, 99) < 0.05, \
        (diff.mean(), np.percentile(diff, 99))
    # Near the ball the map is dark, far from it open: the lists were read.
    assert small.ao[512, 512] < 0.3 and small.ao[40, 40] > 0.99
