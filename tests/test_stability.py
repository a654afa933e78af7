# SPDX-License-Identifier: GPL-3.0-or-later
"""Numerical stability: scale, offset, degenerate input, many directions, huge maps, errors."""
from __future__ import annotations

import numpy as np
import pytest

from bake_helpers import assert_within_sample_tolerance, error_stats, texel_points
from hao_addon.bake import bake
from hao_addon.core import scenes
from hao_addon.core.geometry import TriangleSoup
from hao_addon.core.errors import BakeInputError
from hao_addon.core.bake.settings import BakeSettings
from hao_addon.core.bake.abilities import bakers_with

SIZE, DIRS = 128, 128


def base_scene():
    return scenes.grid_plane(8.0, 16), scenes.uv_sphere(1.0, (0.0, 0.0, 1.0), 48, 24)


def transformed(soup, scale=1.0, offset=(0.0, 0.0, 0.0)):
    return TriangleSoup(soup.positions * scale + np.asarray(offset), soup.uvs, name=soup.name)


# (method, max distance) pairs: each GPU variant with unlimited and with limited distance.
VARIANTS = [("scatter", 0.0), ("scatter", 1.5), ("gather", 0.0), ("gather", 1.5)]


def settings(method, max_distance=0.0, **kw):
    # Each comparison bakes one surface twice with differently fitted light views (another
    # scale, offset or extra degenerate geometry moves the pixel grid); at 4 light-view pixels
    # per texel that sampling difference stays below the bound of assert_same_map.
    return BakeSettings(size=SIZE, directions=DIRS, margin=0, method=method, max_distance=max_distance,
                        **{"view_samples": 4.0, **kw})


@pytest.fixture(scope="module")
def unscaled(gpu_context):
    plane, sphere = base_scene()
    return {v: bake(plane, [sphere], settings(*v), use_cache=False) for v in VARIANTS}


def assert_same_map(a, b, label, rmse_bound=2e-3):
    assert np.isfinite(b.ao).all(), label
    both = a.covered & b.covered
    assert both.sum() > 0.95 * a.covered.sum(), label
    diff = np.abs(a.ao[both] - b.ao[both])
    # The GPU sees normalized coordinates, so only float32 rounding of the transform differs.
    assert np.sqrt((diff**2).mean()) < rmse_bound and diff.max() < 0.05, (label, diff.max())


@pytest.mark.parametrize("scale", [1e-3, 1e-1, 1e2, 1e4])
@pytest.mark.parametrize("variant", VARIANTS)
def test_scale_invariance(unscaled, scale, variant):
    method, md = variant
    plane, sphere = base_scene()
    res = bake(transformed(plane, scale), [transformed(sphere, scale)], settings(method, md * scale), use_cache=False)
    assert_same_map(unscaled[variant], res, f"{variant} scale {scale}")


@pytest.mark.parametrize("variant", VARIANTS)
def test_far_from_origin(unscaled, variant):
    off = (1e5, -1e5, 1e5)
    plane, sphere = base_scene()
    res = bake(transformed(plane, 1.0, off), [transformed(sphere, 1.0, off)], settings(*variant), use_cache=False)
    assert_same_map(unscaled[variant], res, f"{variant} offset 1e5")


@pytest.mark.parametrize("variant", VARIANTS)
def test_degenerate_triangles_nonmanifold_fin_and_zero_uv_area(unscaled, variant):
    plane, sphere = base_scene()
    zero_area = np.array([[[1, 1, 0], [1, 1, 0], [1, 1, 0]], [[0, 0, 0], [1, 0, 0], [2, 0, 0]]], float)
    zero_area_uv = np.array([[[0.1, 0.1], [0.2, 0.1], [0.1, 0.2]], [[0.3, 0.3], [0.4, 0.3], [0.3, 0.4]]])
    # Zero UV area but real surface: a small vertical fin on an interior edge (non-manifold).
    # (It hangs below the plane, so it cannot occlude the baked top side.)
    fin = np.array([[[0, 0, 0], [0, 0.5, -0.5], [0, 0.5, 0]]], float)  # on an interior edge: 3 faces
    fin_uv = np.array([[[0.999, 0.0], [0.999, 0.0], [0.999, 0.0]]])
    messy = TriangleSoup(np.concatenate([plane.positions, zero_area, fin]),
                         np.concatenate([plane.uvs, zero_area_uv, fin_uv]), name="messy")
    res = bake(messy, [sphere], settings(*variant), use_cache=False)
    assert res.stats["zero_area_faces"] == 2 and res.stats["zero_uv_area_faces"] == 1
    # The fin and the zero-area faces widen what the light views fit, so the scatter's light-view
    # pixel grid is not the unscaled bake's: its texel-area splats differ by 0.0023 RMSE (measured
    # with the two replicates); the gather samples texel centres and stays within rounding.
    assert_same_map(unscaled[variant], res, f"{variant} degenerate", 3e-3 if variant[0] == "scatter" else 2e-3)


@pytest.mark.parametrize("method", bakers_with(gpu_only=True))
def test_flipped_normals_bake_the_other_side(gpu_context, method):
    plane, sphere = base_scene()
    flipped = TriangleSoup(plane.positions[:, ::-1], plane.uvs[:, ::-1], name="flipped")
    res = bake(flipped, [sphere], settings(method), use_cache=False)
    # The underside faces away from the sphere: fully open, no NaN, nothing dark.
    assert np.isfinite(res.ao).all()
    np.testing.assert_allclose(res.ao[res.covered], 1.0, atol=1e-5)


@pytest.mark.parametrize("variant", [v for v in VARIANTS if v[1] == 0.0])
def test_overlapping_uv_islands_average(unscaled, variant):
    plane, sphere = base_scene()
    far = transformed(plane, 1.0, (100.0, 0.0, 0.0))  # same UVs, nothing above it
    both = TriangleSoup(np.concatenate([plane.positions, far.positions]), np.concatenate([plane.uvs, far.uvs]))
    res = bake(both, [sphere], settings(variant[0]), use_cache=False)
    ok = res.covered & unscaled[variant].covered
    expected = 0.5 * (unscaled[variant].ao + 1.0)
    assert np.abs(res.ao[ok] - expected[ok]).max() < 0.05
    assert abs(float((res.ao[ok] - expected[ok]).mean())) < 2e-3


@pytest.mark.parametrize("method", bakers_with(gpu_only=True))
def test_4096_directions_no_overflow_or_precision_loss(gpu_context, method):
    plane, sphere = base_scene()
    d = 4096
    # 128^2 at 2 view samples: at 64^2 the gather's shadow-map resolution, not D, bounds its error.
    res = bake(plane, [sphere], BakeSettings(size=128, directions=d, margin=0, view_samples=2.0, method=method),
               use_cache=False)
    pts, mask = texel_points(plane, 128)
    ref = scenes.sphere_on_plane_accessibility(np.linalg.norm(pts - [0, 0, 1.0], axis=-1), 1.0)
    # The gather's slope-scaled bias hides contact occlusion thinner than a few depth-map
    # pixels: next to the contact point its error does not fall with D (measured 0.037 here).
    floor = 0.05 if method == "gather" else 0.0
    assert_within_sample_tolerance(error_stats(res.ao, ref, mask & res.covered), d, f"{method} D=4096", floor)
    lone = bake(plane, [], BakeSettings(size=64, directions=d, margin=0, view_samples=1.0, method=method),
                use_cache=False)
    np.testing.assert_allclose(lone.ao[lone.covered], 1.0, atol=1e-5)


@pytest.mark.parametrize("method", bakers_with(gpu_only=True))
def test_4096_map(gpu_context, method):
    plane = scenes.grid_plane(2.0, 1)
    res = bake(plane, [], BakeSettings(size=4096, directions=16, margin=1, view_samples=1.0, method=method),
               use_cache=False)
    assert res.ao.shape == (4096, 4096) and np.isfinite(res.ao).all()
    assert res.covered.sum() > 0.999 * 4096 * 4096
    np.testing.assert_allclose(res.ao[res.covered], 1.0, atol=1e-5)


def test_bad_input_errors(gpu_context, monkeypatch):
    plane, sphere = base_scene()
    s = BakeSettings(size=64, directions=8)
    with pytest.raises(BakeInputError, match="no faces"):
        bake(TriangleSoup(np.zeros((0, 3, 3)), np.zeros((0, 3, 2)), name="empty"), [], s)
    nan = plane.positions.copy()
    nan[3, 1, 2] = np.nan
    with pytest.raises(BakeInputError, match="NaN"):
        bake(TriangleSoup(nan, plane.uvs), [], s)
    with pytest.raises(BakeInputError, match="occluder|NaN"):
        bad_occ = TriangleSoup(sphere.positions * np.inf, None, name="inf")
        bake(plane, [bad_occ], s)
    with pytest.raises(BakeInputError, match="no UV map"):
        bake(TriangleSoup(plane.positions, None), [], s)
    with pytest.raises(BakeInputError, match="zero area"):
        bake(TriangleSoup(plane.positions, np.zeros_like(plane.uvs)), [], s)
    with pytest.raises(ValueError, match="map size"):
        bake(plane, [], BakeSettings(size=20000))
    monkeypatch.setenv("HAO_GPU_MEMORY_BUDGET", "1")  # MiB
    with pytest.raises(BakeInputError, match="GPU memory"):
        bake(plane, [], BakeSettings(size=1024, directions=8), use_cache=False)
    monkeypatch.delenv("HAO_GPU_MEMORY_BUDGET")
    import gpu
    monkeypatch.setattr(gpu.capabilities, "max_texture_size_get", lambda: 512)
    with pytest.raises(BakeInputError, match="texture limit of 512"):
        bake(plane, [], BakeSettings(size=1024, directions=8), use_cache=False)
