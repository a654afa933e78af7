# SPDX-License-Identifier: GPL-3.0-or-later
"""Bent normals (core/bake/estimators.BentNormals): the cosine-weighted mean unoccluded
direction per texel, from the same directions and sums as the AO, on every backend that
bakes it (the gather and the reference; the scatter refuses)."""
from __future__ import annotations

import numpy as np
import pytest

from bake_helpers import texel_points
from hao_addon.bake import bake
from hao_addon.core import scenes
from hao_addon.core.errors import BakeInputError
from hao_addon.core.bake.estimators import AMBIENT_OCCLUSION, BENT_NORMALS
from hao_addon.core.bake.settings import BakeSettings
from hao_addon.core.bake.plan import make_plan
from hao_addon.core.bake.abilities import bakers_with
from test_bake_analytic import floor_and_wall

# The floor at the foot of an infinitely tall, wide wall sees the quarter-sphere away from
# it: under Malley's mapping a uniform half-disk, mean x -4 / (3 pi), mean z 2 / 3, so the
# bent normal leans atan(2 / pi) = 32.48 degrees from the normal, away from the wall.
WALL_TILT_DEG = float(np.degrees(np.arctan(2.0 / np.pi)))


def angles_deg(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Angles between unit vectors (..., 3)."""
    return np.degrees(np.arccos(np.clip((a * b).sum(-1), -1.0, 1.0)))


@pytest.mark.parametrize("method", bakers_with("bent-normals"))
def test_lone_plane_bends_nowhere(gpu_context, method):
    """Nothing occludes: the bent normal is the normal, up to the direction set's own
    asymmetry (a Fibonacci set of 256 is symmetric about any axis to about 0.1 degree)."""
    plane = scenes.grid_plane(4.0, 8)
    size = 32 if method == "reference" else 128
    res = bake(plane, [], BakeSettings(size=size, directions=256, method=method, margin=0, bent_normals=True),
               use_cache=False)
    assert res.bent_normals.shape == (size, size, 3) and res.bent_normals.dtype == np.float32
    tilt = angles_deg(res.bent_normals[res.covered], np.array([0.0, 0.0, 1.0]))
    assert tilt.max() < 0.25, tilt.max()
    np.testing.assert_allclose(res.ao[res.covered], 1.0, atol=1e-5)


@pytest.mark.parametrize("method", bakers_with("bent-normals"))
def test_floor_at_a_wall_leans_away_by_the_analytic_angle(gpu_context, method):
    floor, wall = floor_and_wall()
    size = 16 if method == "reference" else 64
    res = bake(floor, [wall], BakeSettings(size=size, directions=1024, method=method, margin=0, bent_normals=True),
               use_cache=False)
    _pts, mask = texel_points(floor, size)
    bent = res.bent_normals[mask & res.covered]
    expected = np.array([-np.sin(np.radians(WALL_TILT_DEG)), 0.0, np.cos(np.radians(WALL_TILT_DEG))])
    error = angles_deg(bent, expected)
    assert error.max() < 1.0, (error.max(), angles_deg(bent, np.array([0.0, 0.0, 1.0])).mean())


def test_bent_normals_leave_the_ao_unchanged_and_need_a_gather(gpu_context):
    """One pass, both outputs: the AO channel is the same arithmetic (bit-identical map);
    Auto picks the gather even with a max distance; the scatter refuses."""
    floor, wall = floor_and_wall(width=20.0, height=10.0)
    kw = dict(size=64, directions=64, margin=2)
    plain = bake(floor, [wall], BakeSettings(method="gather", **kw), use_cache=False)
    both = bake(floor, [wall], BakeSettings(method="gather", bent_normals=True, **kw), use_cache=False)
    np.testing.assert_array_equal(plain.ao, both.ao)
    assert plain.bent_normals is None
    assert make_plan(floor, [wall], BakeSettings(max_distance=1.0, bent_normals=True, **kw)).method == "gather"
    assert make_plan(floor, [wall], BakeSettings(max_distance=1.0, **kw)).method == "scatter"
    with pytest.raises(BakeInputError, match="histogram scatter cannot bake bent normals"):
        bake(floor, [wall], BakeSettings(method="scatter", bent_normals=True, **kw), use_cache=False)


def test_bent_estimator_terms_and_fallback():
    """numpy twin: the terms of two directions, and a receiver that sees nothing falls back
    to the mean open direction (sum(w omega)), never a zero vector."""
    weight, visible = np.array([0.5, 0.5]), np.array([1.0, 0.0])
    omega = np.array([0.6, 0.0, 0.8])
    terms = BENT_NORMALS.terms(weight, visible, omega)
    np.testing.assert_allclose(terms[0], [0.5, 0.3, 0.0, 0.4, 0.3, 0.0, 0.4, 0.5])
    np.testing.assert_allclose(terms[1], [0.0, 0.0, 0.0, 0.0, 0.3, 0.0, 0.4, 0.5])
    np.testing.assert_allclose(BENT_NORMALS.bent(terms), [[0.6, 0.0, 0.8], [0.6, 0.0, 0.8]])
    np.testing.assert_allclose(BENT_NORMALS.ratio(terms)[0], AMBIENT_OCCLUSION.ratio(terms[:, [0, 7]])[0])


def test_gather_matches_the_reference_on_the_rocker_arm(gpu_context):
    """Same directions, two ways of finding visibility: the bent normals agree to the
    issue's target (angular RMSE <= 3 degrees at 256 directions) over the interior texels
    where anything occludes."""
    from hao_addon.core.objfile import obj_soup
    from pathlib import Path

    size = 128
    soup = obj_soup(Path(__file__).parent / "data" / "rocker-arm.obj", uvs="auto", size=size)
    kw = dict(size=size, directions=256, margin=0, bent_normals=True)
    gather = bake(soup, [], BakeSettings(method="gather", **kw), use_cache=False)
    ref = bake(soup, [], BakeSettings(method="reference", **kw), use_cache=False)
    _pts, mask = texel_points(soup, size, rings=1)
    mask &= gather.covered & ref.covered & (ref.ao < 0.95)
    error = angles_deg(gather.bent_normals[mask], ref.bent_normals[mask])
    rmse = float(np.sqrt((error ** 2).mean()))
    print(f"bent normals, gather vs reference: angular RMSE {rmse:.2f} deg over {int(mask.sum())} texels")
    assert mask.sum() > 1000 and rmse <= 3.0, (rmse, int(mask.sum()))


def _bent_job(scene, obj, occluders="visible", **options):
    import bpy
    from conftest import small_settings
    from hao_addon.blender.bake_job import BakeJob

    settings = small_settings(scene, method='gather', directions=128, bent_normals=True, occluders=occluders,
                              **options)
    job = BakeJob(settings.to_request([obj]), bpy.context.evaluated_depsgraph_get)
    job.run()
    return job


def test_tangent_space_map_decodes_to_the_object_space_map(scene):
    """Blender's Normal Map node decodes normalize(c.x T + c.y B + c.z N) with the UV map's
    MikkTSpace tangents (Mesh.calc_tangents): decoded so, the tangent-space map is the
    object-space map, on a rotated, scaled, smooth sphere bent by a box beside it."""
    import bpy
    from hao_addon.blender import mesh_data
    from hao_addon.core.bake.tangent_space import tangent_frames, to_object_space
    from hao_addon.core.bake.uv_raster import texel_surface_samples

    bpy.ops.mesh.primitive_uv_sphere_add(segments=24, ring_count=12, location=(0.0, 0.0, 0.0))
    ball = bpy.context.active_object
    bpy.ops.object.shade_smooth()
    ball.rotation_euler = (0.3, 0.5, 0.7)
    ball.scale = (1.0, 1.5, 0.8)
    bpy.ops.mesh.primitive_cube_add(size=1.0, location=(1.6, 0.0, 0.0))
    tangent = _bent_job(scene, ball)
    obj_space = _bent_job(scene, ball, bent_space="object")
    (_o, uv_name, result), = tangent.results
    dg = bpy.context.evaluated_depsgraph_get()
    target = mesh_data.evaluated_soup(ball, dg, uv_name)
    tangents = mesh_data.corner_tangents(ball, dg, uv_name)
    face, bary, _ = texel_surface_samples(target.uvs, result.ao.shape[0])
    valid = result.covered & (face >= 0)
    c = tangent.maps["bent"][ball.name][valid, :3] * 2.0 - 1.0
    frames = tangent_frames(face[valid], bary[valid], tangents, target.normals)
    world = np.einsum("mk,mkd->md", c, frames)
    linear = np.array(ball.matrix_world)[:3, :3]
    decoded = to_object_space(world, linear)
    expected = obj_space.maps["bent"][ball.name][valid, :3] * 2.0 - 1.0
    assert valid.sum() > 4000 and result.ao[valid].min() < 0.8  # the box bends a part of it
    assert angles_deg(decoded, expected / np.linalg.norm(expected, axis=1, keepdims=True)).max() < 0.05


def test_lone_plane_tangent_map_is_flat_blue_and_directx_flips_green(scene):
    import bpy

    bpy.ops.mesh.primitive_plane_add(size=2.0)
    plane = bpy.context.active_object
    plane.rotation_euler = (0.4, 0.0, 1.0)
    job = _bent_job(scene, plane)
    (_o, _uv, result), = job.results
    rgb = job.maps["bent"][plane.name][result.covered, :3]
    np.testing.assert_allclose(rgb, np.broadcast_to([0.5, 0.5, 1.0], rgb.shape), atol=0.003)
    images = {i.name for i in job.commit()}
    assert {f"{plane.name}_AO", f"{plane.name}_BentNormals"} <= images
    bpy.ops.mesh.primitive_cube_add(size=0.5, location=(0.5, 0.5, 0.3))  # bends the plane's normals
    opengl = _bent_job(scene, plane)
    directx = _bent_job(scene, plane, bent_convention="directx")
    a, b = opengl.maps["bent"][plane.name], directx.maps["bent"][plane.name]
    np.testing.assert_allclose(b[..., 1], 1.0 - a[..., 1], atol=1e-6)
    np.testing.assert_array_equal(a[..., [0, 2, 3]], b[..., [0, 2, 3]])
    assert np.abs(a[..., 1] - 0.5).max() > 0.02


@pytest.mark.parametrize("variant", ["max_distance", "anti_aliasing", "selected_to_active"])
def test_bent_normals_in_every_gather_variant_match_the_reference(gpu_context, variant):
    """The depth-list variant (max distance), uploaded sub-texel receivers and Selected to
    Active carry the same eight sums: gather and reference agree where anything occludes."""
    from hao_addon.bake import HighToLow

    floor, wall = floor_and_wall(width=20.0, height=10.0)
    kw = dict(size=24, directions=256, margin=0, bent_normals=True)
    high_to_low = None
    if variant == "max_distance":
        kw.update(max_distance=1.0, falloff="wendland")
    elif variant == "anti_aliasing":
        kw.update(samples_per_texel=4)
    else:  # a plane above the floor projects onto it, its texels 0.3 to 2.3 from the wall
        # (nearer ones are within two light-view pixels of it, where the gather's depth test
        # cannot resolve contact: bake_helpers' max_floor)
        low = scenes.grid_plane(2.0, 4, z=0.3)
        low.positions[:, :, 0] -= 1.3
        high_to_low = HighToLow([floor, wall])
        floor, wall = low, None
        kw.update(cage_extrusion=0.0, max_ray_distance=0.0)
    occluders = [] if wall is None else [wall]
    gather = bake(floor, occluders, BakeSettings(method="gather", **kw), use_cache=False, high_to_low=high_to_low)
    ref = bake(floor, occluders, BakeSettings(method="reference", **kw), use_cache=False, high_to_low=high_to_low)
    mask = gather.covered & ref.covered & (ref.ao < 0.97)
    error = angles_deg(gather.bent_normals[mask], ref.bent_normals[mask])
    assert mask.sum() > 50 and float(np.sqrt((error ** 2).mean())) < 2.0, (float(np.sqrt((error ** 2).mean())), int(mask.sum()))
    leaning = angles_deg(ref.bent_normals[mask], np.array([0.0, 0.0, 1.0]))
    assert leaning.mean() > 5.0  # the wall bends them: the check is not vacuous
