# SPDX-License-Identifier: GPL-3.0-or-later
"""Cycles' shadow-terminator geometry offset (core/bake/terminator.py): the lift's geometry,
its GLSL twin, and that the bakes match Cycles' own with it and do not without it."""
from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from hao_addon.core import scenes
from hao_addon.core.bake.plan import make_plan
from hao_addon.core.bake.receivers import uv_receivers
from hao_addon.core.bake.settings import BakeSettings
from hao_addon.core.bake.terminator import lift_amount, smooth_surface_lift
from hao_addon.core.geometry import TriangleSoup, face_normals_areas
from test_shading_normals import _bake_case, _rmse_bias, cycles_truth


def _smooth_sphere(segments: int = 16, rings: int = 8) -> TriangleSoup:
    """A coarse UV sphere of radius 1 shaded smooth (radial corner normals)."""
    s = scenes.uv_sphere(1.0, (0.0, 0.0, 0.0), segments, rings)
    return TriangleSoup(s.positions, s.uvs, "sphere", s.positions / np.linalg.norm(s.positions, axis=2, keepdims=True))


def _random_points(soup: TriangleSoup, seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """(points (F, 3), bary (F, 3)): one random point per facet."""
    bary = np.random.default_rng(seed).dirichlet((1.0, 1.0, 1.0), soup.face_count)
    return np.einsum("mk,mkd->md", bary, soup.positions), bary


def test_flat_facets_are_not_lifted():
    plane = scenes.grid_plane(2.0, 4)
    normals, _ = face_normals_areas(plane.positions)
    corners = np.repeat(normals[:, None, :], 3, axis=1)
    _points, bary = _random_points(plane)
    np.testing.assert_array_equal(smooth_surface_lift(plane.positions, corners, bary, normals), 0.0)


def test_lift_raises_a_coarse_sphere_s_facets_towards_the_sphere():
    """16 x 8 segments: facets lie up to 0.037 (the sagitta) inside the unit sphere. Every
    point is lifted outwards, none beyond the sphere by more than the largest sagitta, and on
    average the lifted points are closer to the sphere than the facets (measured: 0.009 vs
    0.020; Cycles' parabola-and-envelope overshoots a sphere)."""
    sphere = _smooth_sphere()
    facet_normals, _ = face_normals_areas(sphere.positions)
    points, bary = _random_points(sphere)
    lift = smooth_surface_lift(sphere.positions, sphere.normals, bary, facet_normals)
    sagitta = 1.0 - np.linalg.norm(points, axis=1)
    lifted = np.linalg.norm(points + lift, axis=1) - 1.0
    assert (np.einsum("md,md->m", lift, facet_normals) > 0.0).all()
    assert lifted.max() <= sagitta.max()
    assert np.abs(lifted).mean() < 0.6 * sagitta.mean()


def test_lift_amount_is_cycles_ramp():
    cutoff = 0.1
    # Steep enough above the facet and the shading hemisphere: never lifted.
    assert lift_amount(np.array(0.5), np.array(0.5), cutoff) == 0.0
    # At or below the facet, well inside the shading hemisphere: fully lifted.
    assert lift_amount(np.array(0.5), np.array(0.0), cutoff) == 1.0
    assert lift_amount(np.array(0.5), np.array(-0.3), cutoff) == 1.0
    # Grazing the facet: a linear ramp 1 - cos_true / cutoff.
    assert lift_amount(np.array(0.5), np.array(0.05), cutoff) == pytest.approx(0.5)
    # Near the shading terminator: 2 - (cos_true + cos_shading) / cutoff, continuous at the cutoff.
    assert lift_amount(np.array(0.05), np.array(0.12), cutoff) == pytest.approx(0.3)
    below, above = lift_amount(np.array([0.1 - 1e-9, 0.1]), np.array([0.1, 0.1]), cutoff)
    assert below == pytest.approx(above, abs=1e-6)
    assert (lift_amount(np.array([0.5, 0.01]), np.array([-1.0, 0.0]), 0.0) == 0.0).all()


def test_gpu_texel_list_lifts_like_numpy(gpu_context):
    """The gather's UV-space raster computes each entry's lift in GLSL
    (gpu_shaders/bake_terminator.glsl); it equals the numpy twin at the same texel centres."""
    from hao_addon.gpu import util
    from hao_addon.gpu.bake_gather import GatherBaker

    plan = make_plan(_smooth_sphere(), [], BakeSettings(size=64, directions=16, method="gather", margin=0))
    assert plan.lifts_terminator
    baker = GatherBaker(plan)
    try:
        assert baker.stats["terminator_lift"] is True and baker.stats["cpu_receivers"] is False
        n = baker.entry_count
        lift = util.texture_to_numpy(baker.entry_lift, np.float32).reshape(-1, 4)[:n, :3]
        texel = util.texture_to_numpy(baker.entry_texel, np.uint32).ravel()[:n]
    finally:
        baker.free()
    flat = (texel >> 16).astype(np.int64) * 64 + (texel & 0xFFFF)
    cpu = uv_receivers(plan.target_positions, plan.target_uvs, plan.target_faces, plan.target_corners, 64, 1, True)
    by_texel = dict(zip(cpu.texel.tolist(), cpu.lift))
    # Texels on a triangle edge may go to either neighbour in the two rasterizers: compare
    # those the CPU lists once (the sphere's UV layout does not overlap).
    once = np.bincount(cpu.texel, minlength=64 * 64) == 1
    keep = once[flat]
    assert keep.mean() > 0.9 and np.abs(lift).max() > 1e-3
    expected = np.array([by_texel[t] for t in flat[keep]])
    np.testing.assert_allclose(lift[keep], expected, atol=2e-6)


@pytest.mark.release_independent
def test_reference_matches_cycles_default_only_with_the_offset(gpu_context):
    """Spot shaded smooth, Cycles' default offset (0.1): the ray-traced reference's bias
    against Cycles is +0.0001 with the lift and -0.0017 without it (256 directions; Cycles'
    two-seed mean has a noise of ~1e-5 on a 26k-texel mean)."""
    res, truth, mask = _bake_case("spot_smooth", "reference")
    flat, _, _ = _bake_case("spot_smooth", "reference", terminator_offset=0.0)
    t = cycles_truth(truth)[0][mask]
    assert res.stats["rays_lifted"] > 0 and flat.stats["rays_lifted"] == 0
    assert abs(_rmse_bias(res.ao[mask], t)[1]) < 0.0007
    assert _rmse_bias(flat.ao[mask], t)[1] < -0.0010


def test_gather_without_the_offset_misses_cycles_default_on_bent_normals(gpu_context):
    """Spot with custom normals at Cycles' default offset is 0.037 brighter than with it off:
    the gather matches it (tests/test_shading_normals.py) only with the lift."""
    res, truth, mask = _bake_case("spot_custom_default", "gather", terminator_offset=0.0)
    t = cycles_truth(truth)[0][mask]
    assert res.stats["terminator_lift"] is False
    assert _rmse_bias(res.ao[mask], t)[1] < -0.02


def _set_cycles_terminator(obj, value: float) -> None:
    """Set the offset where the running Blender's Cycles reads it (compat.object_terminator_offset)."""
    if "shadow_terminator_geometry_offset" in obj.bl_rna.properties:
        obj.shadow_terminator_geometry_offset = value
    else:
        obj.cycles.shadow_terminator_geometry_offset = value


def test_blender_bakes_use_each_objects_own_terminator_offset(scene):
    """As Cycles: the baked object's Shadow Terminator Geometry Offset (Object > Shading), the
    sources' largest in Selected to Active; Terminator 'setting' uses the panel's value.
    The bake with the object's 0.0 is the bake with the setting 0.0, and differs from 0.1."""
    import bpy
    from conftest import small_settings, soup_to_object
    from hao_addon import compat
    from hao_addon.blender.bake_job import BakeJob
    from hao_addon.blender.bake_request import terminator_settings

    obj = soup_to_object(_smooth_sphere(), "Ball")
    for poly in obj.data.polygons:
        poly.use_smooth = True
    high = soup_to_object(_smooth_sphere(), "High")
    settings = small_settings(scene, method='gather', directions=64)
    _set_cycles_terminator(obj, 0.0)
    _set_cycles_terminator(high, 0.35)
    assert compat.object_terminator_offset(obj) == 0.0
    base = settings.to_settings()
    assert base.terminator == "object" and base.terminator_offset == pytest.approx(0.1)
    assert terminator_settings(base, [obj]).terminator_offset == 0.0
    assert terminator_settings(base, [obj, high]).terminator_offset == pytest.approx(0.35)
    assert terminator_settings(replace(base, terminator="setting"), [obj]).terminator_offset == pytest.approx(0.1)

    def bake_map(**kw):
        for k, v in kw.items():
            setattr(settings, k, v)
        job = BakeJob(settings.to_request([obj]), bpy.context.evaluated_depsgraph_get)
        job.run()
        (_obj, _uv, result), = job.results
        return result

    own = bake_map(terminator='object')
    assert own.stats["terminator_lift"] is False  # the object's 0.0: nothing lifted
    fixed = bake_map(terminator='setting', terminator_offset=0.0)
    np.testing.assert_array_equal(own.ao, fixed.ao)
    lifted = bake_map(terminator_offset=0.1)
    assert lifted.stats["terminator_lift"] is True and np.abs(lifted.ao - own.ao).max() > 0.01

