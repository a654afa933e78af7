# SPDX-License-Identifier: GPL-3.0-or-later
"""Cascades of viewport HAO (core/hao/cascades.py): placement, the GPU march over them against
its numpy twin and against one fine grid, and what a camera move or a moving object makes
voxelize again."""
from __future__ import annotations

import dataclasses

import numpy as np

from hao_addon.core import scenes
from hao_addon.core.hao.ao_pattern import cascade_march_reference
from hao_addon.core.hao.cascades import MIN_REACH_VOXELS, SNAP_VOXELS, Focus, cascade_specs, contains
from hao_addon.core.hao.view_scene import object_from_soup
from hao_addon.core.hao.view_settings import ViewAOSettings
from test_hao import low_res_samples, view

EYE, TARGET = (1.6, -2.2, 1.3), (0.0, 0.0, 0.7)


def _scene():
    """A box standing on a 40-unit floor, the camera a few units away: the floor is the region."""
    floor = scenes.grid_plane(40.0, 8, name="floor")
    box = scenes.box((-0.3, -0.3, 0.0), (0.3, 0.3, 1.5), name="box")
    return [object_from_soup(floor, "floor"), object_from_soup(box, "box")]


def test_cascades_nest_around_the_focus_and_stop_where_they_would_not_cover_it():
    lo, hi = np.array([-20.0, -20.0, 0.0]), np.array([20.0, 20.0, 2.0])
    specs = cascade_specs(lo, hi, 128, 6, Focus((3.0, 1.0, 0.5), 1.0))
    assert len(specs) == 5  # 40 / 2^4 = 2.5 still spans 2 focus radii; 1.25 would not
    for fine, coarse in zip(specs, specs[1:]):
        assert fine.voxel == coarse.voxel / 2
        f_lo, c_lo = np.asarray(fine.origin), np.asarray(coarse.origin)
        assert np.all(f_lo >= c_lo - 1e-9)
        assert np.all(f_lo + np.asarray(fine.dims) * fine.voxel <= c_lo + np.asarray(coarse.dims) * coarse.voxel + 1e-9)
        assert contains(fine, np.array([3.0, 1.0, 0.5]))
    assert cascade_specs(lo, hi, 128, 6, None) == specs[-1:]
    assert cascade_specs(lo, hi, 128, 1, Focus((3.0, 1.0, 0.5), 1.0)) == specs[-1:]
    # Each cascade sits on its parent's lattice of SNAP_VOXELS voxels, so a small move of the
    # focus leaves it where it was.
    for fine, coarse in zip(specs, specs[1:]):
        steps = (np.asarray(fine.origin) - np.asarray(coarse.origin)) / (SNAP_VOXELS * coarse.voxel)
        np.testing.assert_allclose(steps, np.round(steps), atol=1e-9)
    assert cascade_specs(lo, hi, 128, 6, Focus((3.002, 1.001, 0.5), 1.0)) == specs


def test_a_short_distance_adds_finer_cascades_until_it_spans_enough_voxels():
    """Where d_max spans a few voxels, finer cascades are added around the focus even though
    they cannot cover the whole focus area, until d_max spans MIN_REACH_VOXELS voxels."""
    lo, hi = np.array([-20.0, -20.0, 0.0]), np.array([20.0, 20.0, 2.0])
    wide = Focus((3.0, 1.0, 0.5), 15.0)  # no finer cascade (20 units) covers 30 units
    assert len(cascade_specs(lo, hi, 128, 6, wide)) == 1
    voxel = cascade_specs(lo, hi, 128, 1, None)[0].voxel
    for reach, expected in ((2.0, 3), (5.0, 2), (MIN_REACH_VOXELS, 1), (0.0, 1)):  # voxels of one grid
        specs = cascade_specs(lo, hi, 128, 6, wide, max_distance=reach * voxel)
        assert len(specs) == expected, reach
        assert 0.0 == reach or reach * voxel / specs[0].voxel >= MIN_REACH_VOXELS
        assert contains(specs[0], np.array([3.0, 1.0, 0.5]))
    assert len(cascade_specs(lo, hi, 128, 2, wide, max_distance=2.0 * voxel)) == 2  # the count still caps it


def test_the_march_over_cascades_equals_its_numpy_twin(renderer):
    settings = ViewAOSettings(rays=16, max_distance=0.0, grid=64, filter_size=0, steps=1000)
    vp, w, h = view(EYE, target=TARGET, width=320, height=240, fov=0.7)
    renderer.render(_scene(), vp, w, h, settings)
    assert len(renderer.cascade_specs) == 4
    pts, nrm, ao = low_res_samples(renderer, settings)
    grids = [(renderer.voxels.read_grid(0, k), np.asarray(c.origin), c.voxel)
             for k, c in enumerate(renderer.cascade_specs)]
    ref = cascade_march_reference(grids, pts, nrm, settings.rays, settings.spread, settings.max_distance)
    which = np.array([next(k for k, c in enumerate(renderer.cascade_specs) if contains(c, p)) for p in pts])
    assert all((which == k).sum() > 100 for k in range(4))  # every cascade holds receivers
    assert np.mean(np.abs(ao - ref) > 1e-4) < 0.001
    assert renderer.sampling.counts()[1] == 0 and ao[which == 0].min() < 0.5


def test_cascades_agree_with_one_fine_grid_where_both_cover(renderer):
    """Receivers in the finest cascade with rays that stay in it (d_max 0.5 from points at
    least that far inside its box) get the AO of one grid as fine over the whole region."""
    settings = ViewAOSettings(rays=64, max_distance=0.5, grid=64, filter_size=0)
    vp, w, h = view(EYE, target=TARGET, width=320, height=240, fov=0.7)
    objects = _scene()
    renderer.render(objects, vp, w, h, settings)
    finest = renderer.cascade_specs[0]
    pts, _, ao = low_res_samples(renderer, settings)
    g = finest.to_grid(pts)
    margin = settings.max_distance / finest.voxel
    deep = np.all((g >= margin) & (g < np.asarray(finest.dims) - margin), axis=1)
    fine = settings.with_(cascades=1, grid=int(round(40.0 / finest.voxel)) + 2)
    renderer.render(objects, vp, w, h, fine)
    assert abs(renderer.spec.voxel - finest.voxel) < 0.01 * finest.voxel
    _, _, ao_fine = low_res_samples(renderer, fine)
    d = ao[deep] - ao_fine[deep]
    assert deep.sum() > 1000 and ao[deep].min() < 0.9
    # Same voxel size (measured: the same lattice here, RMSE 2e-6); a grid offset by a
    # fraction of a voxel would move surfaces by that much.
    assert np.sqrt((d * d).mean()) < 0.02 and abs(d.mean()) < 0.005


def test_a_camera_move_or_a_distant_change_voxelizes_only_what_it_must(renderer):
    settings = ViewAOSettings(rays=8, max_distance=0.0, grid=64)
    objects = _scene()
    renderer.render(objects, *view(EYE, target=TARGET, width=160, height=120, fov=0.7), settings)
    voxelized = renderer.stats["cascades_voxelized"]
    assert voxelized == len(renderer.cascade_specs) == 4
    renderer.render(objects, *view((1.62, -2.21, 1.3), target=TARGET, width=160, height=120, fov=0.7), settings)
    assert renderer.stats["gbuffer"] == 2 and renderer.stats["cascades_voxelized"] == voxelized
    # A ball far out on the floor lies in the coarsest cascade only: that one is voxelized again.
    ball = object_from_soup(scenes.uv_sphere(0.5, (15.0, 15.0, 0.5), 16, 8, name="ball"), "ball")
    renderer.render(objects + [ball], *view((1.62, -2.21, 1.3), target=TARGET, width=160, height=120, fov=0.7),
                    settings)
    assert renderer.stats["cascades_voxelized"] == voxelized + 1
    moved = dataclasses.replace(ball, key="moved", offset=ball.offset + 0.5)
    renderer.render(objects + [moved], *view((1.62, -2.21, 1.3), target=TARGET, width=160, height=120, fov=0.7),
                    settings)
    assert renderer.stats["cascades_voxelized"] == voxelized + 2


def test_a_shorter_distance_alone_places_finer_cascades(renderer):
    """d_max is part of the placement's key: changing only it re-places the cascades."""
    floor = object_from_soup(scenes.grid_plane(4.0, 8, name="floor"), "floor")
    box = object_from_soup(scenes.box((-0.3, -0.3, 0.0), (0.3, 0.3, 1.5), name="box"), "box")
    settings = ViewAOSettings(rays=8, max_distance=0.0, grid=64)
    camera = view((4.0, -5.5, 3.2), target=TARGET, width=160, height=120, fov=0.7)
    renderer.render([floor, box], *camera, settings)
    assert len(renderer.cascade_specs) == 1  # the view spans the floor
    placed = renderer.stats["cascades"]
    short = 2.0 * renderer.cascade_specs[0].voxel
    renderer.render([floor, box], *camera, settings.with_(max_distance=short))
    assert renderer.stats["cascades"] == placed + 1
    assert len(renderer.cascade_specs) == 3 and short / renderer.cascade_specs[0].voxel >= MIN_REACH_VOXELS
