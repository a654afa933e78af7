# SPDX-License-Identifier: GPL-3.0-or-later
"""Work skipped when the scene does not need it: far occluders, empty texels, re-bakes."""
from __future__ import annotations

import time

import numpy as np

from hao_addon.bake import bake
from hao_addon.core import scenes
from hao_addon.core.geometry import TriangleSoup
from hao_addon.core.bake.settings import BakeSettings


def test_occluders_beyond_max_distance_are_not_drawn(gpu_context):
    plane = scenes.grid_plane(4.0, 8)
    near = scenes.uv_sphere(0.5, (0.0, 0.0, 0.6), 24, 12)
    far = scenes.uv_sphere(0.5, (0.0, 0.0, 9.0), 24, 12)  # 8.5 above the plane: out of reach
    s = BakeSettings(size=64, directions=64, max_distance=2.0, margin=0)
    with_far = bake(plane, [near, far], s, use_cache=False)
    without = bake(plane, [near], s, use_cache=False)
    assert with_far.stats["occluder_objects_culled"] == 1
    assert with_far.stats["occluder_faces_drawn"] == near.face_count
    np.testing.assert_array_equal(with_far.ao, without.ao)
    # With unlimited distance the far sphere counts and is drawn.
    unlimited = bake(plane, [near, far], BakeSettings(size=64, directions=64, margin=0), use_cache=False)
    assert unlimited.stats["occluder_objects_culled"] == 0
    assert unlimited.stats["occluder_faces_drawn"] == near.face_count + far.face_count


def test_uncovered_texels_cost_nothing(gpu_context):
    """The light-view work follows the covered texels, not the map size: the same mesh at
    the same texel density in a 16x larger map (UVs in a quarter of each axis) rasterizes the
    same number of light-view pixels per direction."""
    plane, sphere = scenes.grid_plane(4.0, 8), scenes.uv_sphere(0.5, (0, 0, 0.5), 24, 12)
    full = bake(plane, [sphere], BakeSettings(size=128, directions=16, margin=0, method="scatter"), use_cache=False)
    corner = TriangleSoup(plane.positions, plane.uvs * 0.25, name="corner")
    small = bake(corner, [sphere], BakeSettings(size=512, directions=16, margin=0, method="scatter"),
                 use_cache=False)
    assert abs(small.stats["covered_texels"] - full.stats["covered_texels"]) < 0.02 * full.stats["covered_texels"]
    ratio = small.stats["view_pixels"] / full.stats["view_pixels"]
    assert 0.97 < ratio < 1.03, ratio


def test_rebake_with_unchanged_input_is_cached(gpu_context):
    plane, sphere = scenes.grid_plane(4.0, 8), scenes.uv_sphere(0.5, (0, 0, 0.5), 24, 12)
    s = BakeSettings(size=256, directions=128)
    t0 = time.perf_counter()
    first = bake(plane, [sphere], s)
    t_first = time.perf_counter() - t0
    t0 = time.perf_counter()
    second = bake(plane, [sphere], s)
    t_second = time.perf_counter() - t0
    assert not first.stats["cache_hit"] and second.stats["cache_hit"]
    np.testing.assert_array_equal(first.ao, second.ao)
    assert t_second < 0.05 * t_first, (t_first, t_second)
    # Any change in geometry, UVs or settings misses the cache.
    moved = TriangleSoup(sphere.positions + [0, 0, 1e-4], None)
    assert not bake(plane, [moved], s).stats["cache_hit"]
    assert not bake(plane, [sphere], BakeSettings(size=256, directions=129)).stats["cache_hit"]


def test_closed_surfaces_skip_back_faces_in_depth_maps(gpu_context):
    """Everything drawn is closed: the scatter's light-view pre-pass draws one side of the
    faces only (those turned away from the light, see plan.depth_map_culls_back_faces), and
    the map equals the one from drawing every face but for a few texels where the light ray
    leaves an occluder within the depth bias of the fragment (a ray grazing the surface just
    behind it): there the bias lets through a direction the full map blocks. Over six seeds
    (pixel-grid jitters): at most 0.1 % of the texels, each by at most one direction's term
    (1 / S_f <= 4 / D), and a mean change under 1e-4."""
    import dataclasses

    from hao_addon.core.bake.plan import make_plan
    from hao_addon.core.bake.seams import finalize_map
    from hao_addon.bakers import baker_for

    torus = scenes.torus(1.0, 0.45, (0, 0, 0), 48, 24)
    tilted = TriangleSoup(torus.positions @ np.array([[1, 0, 0], [0, 0.8, 0.6], [0, -0.6, 0.8]]), torus.uvs)
    method, directions = "scatter", 32
    for seed in range(6):
        plan = make_plan(tilted, [], BakeSettings(size=128, directions=directions, margin=0, method=method, seed=seed))
        assert plan.closed_surfaces and plan.depth_map_culls_back_faces and plan.stats["closed_surfaces"]
        maps = []
        for p in (plan, dataclasses.replace(plan, closed_surfaces=False)):
            baker = baker_for(method)(p)
            try:
                for i in range(p.direction_count):
                    baker.run_direction(i)
                maps.append(finalize_map(*baker.plan.estimator.ratio(baker.accumulated()), 0))
            finally:
                baker.free()
        (culled, covered, _), (full, covered_full, _) = maps
        np.testing.assert_array_equal(covered, covered_full)
        assert 0.3 < culled[covered].min() and culled[covered].mean() < 0.97  # the hole shades the inner ring
        diff = (culled - full)[covered]
        assert (np.abs(diff) > 1e-4).mean() <= 1e-3, seed
        assert np.abs(diff).max() <= 4.0 / directions and abs(diff.mean()) < 1e-4, seed
    # An open occluder (a plane) or a max distance keeps every face in the depth maps.
    plane = scenes.grid_plane(4.0, 4, z=-0.5)
    assert not make_plan(tilted, [plane], BakeSettings(size=64, directions=8)).depth_map_culls_back_faces
    assert not make_plan(tilted, [], BakeSettings(size=64, directions=8, max_distance=1.0)).depth_map_culls_back_faces


def test_gather_draws_averted_faces_only_where_the_light_looks_into_a_hole(gpu_context):
    """Everything drawn bounds solids, but the occluding torus has holes in its top. The light
    views draw light-facing faces plus averted ones only in the chunks behind a hole's outline,
    and the map equals the one from drawing every face. Dropping those chunks too (as if the
    torus were closed) lets light through the holes onto the sphere below: the runs matter."""
    import dataclasses

    from hao_addon.core.bake.plan import make_plan
    from hao_addon.core.bake.seams import finalize_map
    from hao_addon.bakers import baker_for

    sphere = scenes.uv_sphere(0.5, (0.0, 0.0, 0.0), 64, 32)
    segments, sides = 96, 48
    torus = scenes.torus(0.5, 0.25, (0.0, 0.0, 0.9), segments, sides)
    top = sides // 4  # quads (i, top) sit on the top of the tube; every 24th is cut out
    quads = np.array([i * sides + top for i in range(0, segments, 24)])
    holed = TriangleSoup(np.delete(torus.positions, np.concatenate([quads, quads + len(torus.positions) // 2]), axis=0))
    settings = BakeSettings(size=128, directions=64, margin=0, method="gather")
    plan = make_plan(sphere, [holed], settings)
    assert len(plan.holes) == len(quads) and plan.stats["holes"] == len(quads)
    maps, stats = [], []
    for holes in (plan.holes, None, []):
        baker = baker_for("gather")(dataclasses.replace(plan, holes=holes))
        try:
            for i in range(plan.direction_count):
                baker.run_direction(i)
            maps.append(finalize_map(*baker.plan.estimator.ratio(baker.accumulated()), 0))
            stats.append(dict(baker.stats))
        finally:
            baker.free()
    (runs, covered, _), (every_face, _, _), (front_only, _, _) = maps
    np.testing.assert_array_equal(runs, every_face)
    assert 0 < stats[0]["averted_faces_drawn"] < stats[0]["averted_faces_skipped"]
    assert (front_only - every_face)[covered].max() > 0.02  # light leaks through the holes
