# SPDX-License-Identifier: GPL-3.0-or-later
"""GPU bakes of scenes with known AO (both bake variants), and the reference tracer."""
from __future__ import annotations

import numpy as np
import pytest

from bake_helpers import assert_within_sample_tolerance, error_stats, sigma, texel_points
from hao_addon.bake import bake
from hao_addon.core import scenes
from hao_addon.core.geometry import TriangleSoup
from hao_addon.core.reference import reference_accessibility
from hao_addon.core.bake.settings import BakeSettings
from hao_addon.core.bake.abilities import bakers_with, declaration

R = 1.0


def sphere_on_plane():
    return scenes.grid_plane(8.0, 16), scenes.uv_sphere(R, (0.0, 0.0, R))


def floor_and_wall(width=2000.0, height=1000.0):
    floor = scenes.grid_plane(2.0, 8)
    floor.positions[:, :, 0] -= 1.05  # x in [-2.05, -0.05]: distances 0.05 .. 2.05 from the wall
    return floor, scenes.wall(width, height, 0.0)


@pytest.mark.parametrize("method", bakers_with())
@pytest.mark.parametrize("weighting", ["cosine", "uniform"])
def test_lone_plane_is_exactly_open(gpu_context, method, weighting):
    plane = scenes.grid_plane(4.0, 8)
    size = 64 if method == "reference" else 128  # the CPU twin traces size^2 x directions rays
    res = bake(plane, [], BakeSettings(size=size, directions=64, method=method, weighting=weighting, margin=0),
               use_cache=False)
    assert res.covered.sum() > 0.95 * size * size
    # The ratio estimator makes an unoccluded texel exact up to fixed-point rounding (2^-26).
    np.testing.assert_allclose(res.ao[res.covered], 1.0, atol=1e-5)


@pytest.mark.parametrize("method", bakers_with(gpu_only=True))
@pytest.mark.parametrize("directions", [64, 256])
def test_sphere_on_plane_matches_one_minus_r_over_d_cubed(gpu_context, method, directions):
    plane, sphere = sphere_on_plane()
    size = 256
    res = bake(plane, [sphere], BakeSettings(size=size, directions=directions, method=method, margin=0),
               use_cache=False)
    pts, mask = texel_points(plane, size)
    ref = scenes.sphere_on_plane_accessibility(np.linalg.norm(pts - [0, 0, R], axis=-1), R)
    stats = error_stats(res.ao, ref, mask & res.covered)
    assert stats["n"] > 0.9 * size * size
    assert_within_sample_tolerance(stats, directions, f"{method} D={directions}")


@pytest.mark.parametrize("method", bakers_with())
def test_floor_next_to_wall_unlimited(gpu_context, method):
    floor, wall = floor_and_wall()
    size, directions = (64 if method == "reference" else 128), 256
    res = bake(floor, [wall], BakeSettings(size=size, directions=directions, method=method, margin=0), use_cache=False)
    pts, mask = texel_points(floor, size)
    cols = slice(0, size)
    # The wall is finite (2000 x 1000): its exact value differs from 1/2 by up to 1e-3.
    xs = -pts[size // 2, cols, 0]
    ref_line = scenes.finite_wall_accessibility(xs, 0.0, 2000.0, 1000.0)
    assert np.all(np.abs(ref_line - 0.5) < 2e-3)
    ref = np.broadcast_to(ref_line[None, :], (size, size))
    assert_within_sample_tolerance(error_stats(res.ao, ref, mask & res.covered), directions, method)


@pytest.mark.parametrize("method", bakers_with())
@pytest.mark.parametrize("falloff", ["none", "wendland"])
@pytest.mark.parametrize("max_distance", [0.5, 1.0])
def test_floor_next_to_wall_with_max_distance(gpu_context, falloff, max_distance, method):
    floor, wall = floor_and_wall(width=20.0, height=10.0)  # infinite within reach of every texel
    size, directions = (32 if method == "reference" else 128), 256
    res = bake(floor, [wall], BakeSettings(size=size, directions=directions, max_distance=max_distance,
                                           falloff=falloff, margin=0, method=method), use_cache=False)
    if method != "reference":
        assert res.stats["layered"] and res.stats["layer_overflow_pixels"] == 0
    pts, mask = texel_points(floor, size)
    ref = scenes.wall_accessibility(-pts[..., 0].ravel(), max_distance, falloff).reshape(size, size)
    assert_within_sample_tolerance(error_stats(res.ao, ref, mask & res.covered), directions, falloff)


def test_ignore_back_faces(gpu_context):
    floor, wall = floor_and_wall(width=20.0, height=10.0)
    flipped = TriangleSoup(wall.positions[:, ::-1], wall.uvs[:, ::-1], name="flipped wall")  # faces away
    kw = dict(size=64, directions=128, margin=0)
    seen = bake(floor, [flipped], BakeSettings(**kw), use_cache=False)
    ignored = bake(floor, [flipped], BakeSettings(ignore_back_faces=True, **kw), use_cache=False)
    # The floor sees the wall's back: it occludes unless back faces are ignored.
    assert seen.ao[seen.covered].mean() < 0.6
    np.testing.assert_allclose(ignored.ao[ignored.covered], 1.0, atol=1e-5)
    # A front-facing wall occludes either way.
    front = bake(floor, [wall], BakeSettings(ignore_back_faces=True, **kw), use_cache=False)
    assert abs(front.ao[front.covered].mean() - seen.ao[seen.covered].mean()) < 0.02


def test_stretch_correction_nonuniform_uvs(gpu_context):
    """UVs stretched non-uniformly (u -> u^2): the |J| weighting keeps the map a surface
    average, so the analytic answer still holds at the texels' surface points."""
    plane, sphere = sphere_on_plane()
    warped = plane.uvs.copy()
    warped[..., 0] = 0.05 + 0.9 * warped[..., 0] ** 2
    plane = TriangleSoup(plane.positions, warped, name="warped plane")
    size, directions = 256, 256
    res = bake(plane, [sphere], BakeSettings(size=size, directions=directions, margin=0), use_cache=False)
    pts, mask = texel_points(plane, size)
    ref = scenes.sphere_on_plane_accessibility(np.linalg.norm(pts - [0, 0, R], axis=-1), R)
    assert_within_sample_tolerance(error_stats(res.ao, ref, mask & res.covered), directions, "warped")


def test_reference_tracer_on_sphere_on_plane():
    plane, sphere = sphere_on_plane()
    scene = np.concatenate([plane.positions, sphere.positions])
    rho = np.linspace(0.3, 3.5, 12)
    pts = np.stack([rho, np.zeros_like(rho), np.zeros_like(rho)], 1)
    rays = 1024
    got = reference_accessibility(pts, np.tile([0, 0, 1.0], (len(pts), 1)), scene, rays=rays)
    exact = scenes.sphere_on_plane_accessibility(np.linalg.norm(pts - [0, 0, R], axis=1), R)
    # The sphere is a 64x32 polygon (inscribed): its form factor is smaller by up to ~1 %.
    tol = 4 * np.sqrt(exact * (1 - exact) / rays) + 0.01 * (1 - exact) + 1e-3
    assert np.all(np.abs(got - exact) <= tol), (got - exact, tol)


def test_reference_tracer_max_distance_and_backfaces():
    floor, wall = floor_and_wall(width=20.0, height=10.0)
    scene = np.concatenate([floor.positions, wall.positions])
    xs = np.array([0.1, 0.3, 0.6, 0.9])
    pts = np.stack([-xs, np.zeros(4), np.zeros(4)], 1)
    normals = np.tile([0, 0, 1.0], (4, 1))
    for falloff in ("none", "wendland"):
        got = reference_accessibility(pts, normals, scene, rays=1024, max_distance=1.0, falloff=falloff)
        exact = scenes.wall_accessibility(xs, 1.0, falloff)
        assert np.all(np.abs(got - exact) < 4 * np.sqrt(0.25 / 1024)), (falloff, got - exact)
    flipped = np.concatenate([floor.positions, wall.positions[:, ::-1]])
    got = reference_accessibility(pts, normals, flipped, rays=256, ignore_back_faces=True)
    np.testing.assert_allclose(got, 1.0)


def test_first_hits_casts_as_first_hit_does():
    """The reference baker's loop over one direction (first_hits: one BVH cast a ray where no
    rule skips a hit), and the viewport reference's over one point (first_hits_from), give
    first_hit's distances exactly, misses and reach included, with and without back faces
    skipped and a min distance."""
    from mathutils import Vector
    from hao_addon.core.geometry import face_normals_areas
    from hao_addon.core.reference import build_bvh, first_hit, first_hits, first_hits_from
    floor, wall = floor_and_wall(width=20.0, height=10.0)
    scene = np.concatenate([floor.positions, wall.positions[:, ::-1]])  # the wall seen from behind
    ray_cast = build_bvh(scene).ray_cast
    rng = np.random.default_rng(5)
    origins = [Vector(p) for p in np.stack([-rng.uniform(0.05, 2.0, 64), rng.uniform(-1, 1, 64), np.full(64, 1e-6)], 1)]
    offsets = np.full(64, 1e-6)
    direction = np.array([0.6, 0.0, 0.8])
    for faces, min_distance, reach in ((None, 0.0, 1e30), (None, 0.0, 1.0), (face_normals_areas(scene)[0], 0.0, 1e30),
                                       (None, 0.5, 1e30)):
        one = [first_hit(ray_cast, o, direction, reach, 1e-6, faces, min_distance) for o in origins]
        got = first_hits(ray_cast, origins, direction, reach, offsets, faces, min_distance)
        np.testing.assert_array_equal(got, one)
        assert np.isfinite(got).any() or faces is not None
    assert np.isinf(first_hits(ray_cast, origins, direction, 1e30, offsets, face_normals_areas(scene)[0])).all()
    # The viewport reference's loop: one origin, many directions (first_hits_from).
    directions = np.stack([rng.uniform(0.1, 1, 64), rng.uniform(-1, 1, 64), rng.uniform(0.05, 1, 64)], 1)
    directions /= np.linalg.norm(directions, axis=1, keepdims=True)
    near = Vector((-0.3, 0.0, 1e-6))  # within 1.0 of the wall along some of the directions
    for faces, reach in ((None, 1e30), (None, 1.0), (face_normals_areas(scene)[0], 1e30)):
        one = [first_hit(ray_cast, near, d, reach, 1e-6, faces) for d in directions]
        got = first_hits_from(ray_cast, near, directions, reach, 1e-6, faces)
        np.testing.assert_array_equal(got, one)
        assert np.isfinite(got).any() or faces is not None


@pytest.mark.parametrize("directions", [256, 1024])
def test_sigma_bound_catches_a_two_percent_normalization_error(gpu_context, directions):
    """The tolerance is not vacuous: the gather's map of the sphere on the plane passes it,
    and the same map with a 2 % normalization error (every value scaled by 0.98, as a wrong
    constant in the estimator's denominator would) fails it."""
    plane, sphere = sphere_on_plane()
    size = 128
    res = bake(plane, [sphere], BakeSettings(size=size, directions=directions, method="gather", margin=0),
               use_cache=False)
    pts, mask = texel_points(plane, size)
    ref = scenes.sphere_on_plane_accessibility(np.linalg.norm(pts - [0, 0, R], axis=-1), R)
    assert_within_sample_tolerance(error_stats(res.ao, ref, mask & res.covered), directions, "as baked")
    with pytest.raises(AssertionError, match="bias"):
        assert_within_sample_tolerance(error_stats(res.ao * 0.98, ref, mask & res.covered), directions, "2 % off")


@pytest.mark.parametrize("weighting", ["cosine", "uniform"])
def test_gather_batched_directions_equal_one_per_dispatch(gpu_context, monkeypatch, weighting):
    """Testing up to 16 or 4 directions per compute dispatch (10 directions: one batch of 10;
    two batches of 4 and one of 2 padded with two empty slots) adds the same terms in the same
    order as one direction per dispatch."""
    import hao_addon.gpu.bake_gather as bake_gather
    plane, sphere = sphere_on_plane()
    settings = BakeSettings(size=64, directions=10, method="gather", weighting=weighting, margin=0)
    maps = []
    for most, per_dispatch in ((16, 10), (4, 4), (1, 1)):
        monkeypatch.setattr(bake_gather, "VIEWS_PER_DISPATCH", most)
        result = bake(plane, [sphere], settings, use_cache=False)
        assert result.stats["views_per_dispatch"] == per_dispatch
        maps.append(result.ao)
    assert (maps[0] < 0.99).sum() > 100  # the sphere shadows the plane: the test sees occlusion
    np.testing.assert_array_equal(maps[0], maps[1])
    np.testing.assert_array_equal(maps[0], maps[2])


def test_gather_batch_size_follows_the_depth_map_budget():
    """A dispatch's depth maps stay within DEPTH_BATCH_BYTES: 16 views up to 1024^2 pixels,
    4 at 2048^2, one beyond; the directions split into batches of equal size (few padded
    slots); max-distance bakes (depth lists) one per dispatch; a re-bake by difference views in
    pairs (each direction before and after)."""
    from types import SimpleNamespace
    import hao_addon.gpu.bake_gather as bake_gather

    def per_dispatch(side, directions=256, max_distance=0.0, before_drawn=None):
        settings = SimpleNamespace(max_distance=max_distance, directions=directions)
        return bake_gather.views_per_dispatch(SimpleNamespace(max_view_side=side, settings=settings,
                                                              layered=max_distance > 0.0, direction_count=directions,
                                                              before_drawn=before_drawn, classes=1))
    assert [per_dispatch(s) for s in (256, 1024, 1448, 2048, 4096)] == [16, 16, 8, 4, 1]
    assert [per_dispatch(256, d) for d in (1, 8, 16, 20, 64, 96, 100)] == [1, 8, 16, 10, 16, 16, 15]
    assert per_dispatch(256, max_distance=1.0) == 1
    # a re-bake by difference draws each direction before and after: views come in pairs
    assert [per_dispatch(s, before_drawn=()) for s in (256, 2048, 4096)] == [16, 4, 2]


@pytest.mark.parametrize("shading", ["face", "smooth"])
def test_gather_normal_bins_skip_entries_without_changing_the_map(gpu_context, monkeypatch, shading):
    """Dispatching only the texel-list entries whose normal bin can face a batch's views, and
    drawing into the depth maps only the faces of bins that can face the light
    (core/bake/normal_bins.py), gives the same map as testing every entry and drawing every
    face, and skips both. Smooth shading bins each entry by its own shading normal (the
    octahedral cell cones); face shading by its face."""
    import hao_addon.gpu.bake_gather as bake_gather
    sphere = scenes.uv_sphere(1.0, (0.0, 0.0, 1.0), 48, 24)  # normals all round: bins to skip
    if shading == "smooth":
        sphere.normals = sphere.positions - np.array([0.0, 0.0, 1.0])
    # A closed scene (the depth maps cull back faces): the sphere over a box.
    box = scenes.box((-3.0, -3.0, -1.0), (3.0, 3.0, -0.05))
    settings = BakeSettings(size=64, directions=64, method="gather", margin=0)
    # Batches of 4 of a replicate's 32 directions (core/directions.py): 16 directions span half
    # the sphere, and nearly every bin faces one of them.
    monkeypatch.setattr(bake_gather, "VIEWS_PER_DISPATCH", 4)
    maps, stats = [], []
    for binning in (True, False):
        monkeypatch.setattr(bake_gather, "NORMAL_BINNING", binning)
        res = bake(sphere, [box], settings, use_cache=False)
        maps.append(res.ao)
        stats.append(res.stats)
    np.testing.assert_array_equal(maps[0], maps[1])
    assert (maps[0] < 0.9).sum() > 50  # the box shades the sphere's underside
    assert stats[0]["texel_tests_skipped"] > 0.1 * (stats[0]["texel_tests"] + stats[0]["texel_tests_skipped"])
    assert stats[1]["texel_tests_skipped"] == 0
    # Half the faces of a closed scene face away from each light: about that many are skipped.
    assert stats[0]["depth_faces_skipped"] > 0.3 * (stats[0]["depth_faces_drawn"] + stats[0]["depth_faces_skipped"])
    assert stats[1]["depth_faces_skipped"] == stats[1]["depth_faces_drawn"] == 0


@pytest.mark.parametrize("method", bakers_with(gpu_only=True))
def test_wendland_falloff_is_the_papers_kernel(gpu_context, method):
    """The GPU falloff (gpu_shaders/bake_falloff.glsl, shared by both variants) is
    w(x) = (1 - x)^4 (4x + 1), not a kernel of the same shape:
    with d_max past the floor's far edge the weight matters at every texel, and at D = 1024
    the bias bound is five times smaller than what (1 - x)^4 (3x + 1) would add."""
    floor, wall = floor_and_wall(width=20.0, height=10.0)  # a wall that is infinite within reach
    size, directions, max_distance = 128, 1024, 4.0
    res = bake(floor, [wall], BakeSettings(size=size, directions=directions, max_distance=max_distance,
                                           falloff="wendland", margin=0, method=method), use_cache=False)
    pts, mask = texel_points(floor, size)
    xs = -pts[..., 0].ravel()
    ref = scenes.wall_accessibility(xs, max_distance, "wendland").reshape(size, size)
    assert_within_sample_tolerance(error_stats(res.ao, ref, mask & res.covered), directions, "wendland")
    # The check is sharp enough: the same formula with 3x + 1 fails it by bias alone.
    y = (np.arange(4096) + 0.5) / 4096
    distinct, index = np.unique(xs, return_inverse=True)
    s = np.clip(distinct[:, None] / y[None, :] / max_distance, 0.0, 1.0)
    extra = ((1.0 - s) ** 4 * s * 2.0 * np.sqrt(1.0 - y * y)).sum(axis=1) / 4096 / np.pi  # w4 - w3
    mutant = (ref.ravel() + extra[index]).reshape(size, size)
    assert error_stats(mutant, ref, mask & res.covered)["bias"] > 4 * sigma(directions) / 8


@pytest.mark.parametrize("method", bakers_with())
def test_every_baker_returns_the_estimators_sums(gpu_context, method):
    """The bakers find visibility their own way and return the plan's estimator sums per texel
    (core/bake/estimators.py): (size, size, channels), the weight sum last; for ambient
    occlusion the map is their ratio and the numerator never exceeds the weight sum. The bake
    sums its two replicates apart (restart between them) and adds them."""
    from hao_addon.bakers import baker_for
    from hao_addon.core.bake.estimators import AMBIENT_OCCLUSION
    from hao_addon.core.bake.plan import make_plan
    from hao_addon.core.bake.seams import finalize_map
    from hao_addon.core.directions import replicate_sizes
    plane, sphere = sphere_on_plane()
    settings = BakeSettings(size=32, directions=16, method=method, margin=0)
    plan = make_plan(plane, [sphere], settings)
    assert plan.estimator is AMBIENT_OCCLUSION
    baker = baker_for(method)(plan)
    try:
        split = replicate_sizes(plan.direction_count)[0]  # every texel class's directions
        for i in range(split):
            baker.run_direction(i)
        first = baker.accumulated()
        baker.restart()
        for i in range(split, plan.direction_count):
            baker.run_direction(i)
        sums = first + baker.accumulated()
    finally:
        baker.free()
    assert sums.shape == (32, 32, AMBIENT_OCCLUSION.channel_count)
    baked = bake(plane, [sphere], settings, use_cache=False)
    # Texels in contact with the ball are traced exactly after the baker (hao_addon/contact_repair.py).
    from hao_addon.contact_repair import contact_cells
    traced = np.zeros(32 * 32, bool)
    if declaration(method).traces_contacts:
        traced[contact_cells(plan)] = True
        assert baked.stats["contact_texels"] == traced.sum() > 0
    ours = finalize_map(*AMBIENT_OCCLUSION.ratio(sums), 0)[0]
    np.testing.assert_array_equal(ours.reshape(-1)[~traced], baked.ao.reshape(-1)[~traced])
    weight, visible = np.array([0.5, 0.25]), np.array([1.0, 0.0])
    np.testing.assert_array_equal(AMBIENT_OCCLUSION.terms(weight, visible, np.array([0.0, 0.0, 1.0])),
                                  [[0.5, 0.5], [0.0, 0.25]])
    assert (sums[..., 0] <= sums[..., 1] * (1.0 + 1e-6) + 1e-12).all()  # V <= 1


def test_the_scatter_refuses_an_estimator_it_cannot_pack(gpu_context, monkeypatch):
    """The scatter's accumulator packs (numerator <= weight) into one word: another estimator
    gets one clear message, not a wrong map."""
    from hao_addon.core.bake import plan as plan_module
    from hao_addon.core.bake.estimators import Estimator
    from hao_addon.core.errors import BakeInputError
    other = Estimator("bent normals", ("bent_x", "bent_y", "bent_z", "weight"), "ESTIMATOR_TEST_ONLY")
    monkeypatch.setattr(plan_module.BakePlan, "estimator", property(lambda self: other))
    plane, sphere = sphere_on_plane()
    with pytest.raises(BakeInputError, match="ambient occlusion only"):
        bake(plane, [sphere], BakeSettings(size=32, directions=4, method="scatter"), use_cache=False)
