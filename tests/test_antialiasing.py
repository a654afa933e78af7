# SPDX-License-Identifier: GPL-3.0-or-later
"""Anti-aliasing (samples_per_texel 1, 4, 9, 16): stratified sub-texel points, averaged.
Where AO jumps inside a texel (the ridge of a roof, at an angle to the texel grid) one centre
sample takes one side's value; the average of k x k points is the texel's mean. The truth is
each texel's area on either side (64 points) times that side's value, which is constant
across a side (the reference's, with the same direction set), so the only difference left
is how each texel is sampled. (At an occluder's foot the gather's error is
its shadow-map resolution instead, which more samples per texel do not change.)"""
from __future__ import annotations

import numpy as np
import pytest

from hao_addon.bake import bake
from hao_addon.core import scenes
from hao_addon.core.geometry import TriangleSoup
from hao_addon.core.bake.receivers import sub_texel_grid, texel_sample_points
from hao_addon.core.bake.settings import BakeSettings
from hao_addon.core.bake.uv_raster import SAMPLE_INSET

SIZE = 48
DIRECTIONS = 128  # two replicates of 64: the sides' values within 0.02 of (1 + cos) / 2
PHI = np.radians(20.0)  # the ridge's angle to the texel grid
SLOPES = (np.radians(30.0), np.radians(70.0))  # a gentle and a steep roof side
HEIGHT = 4.5  # of the ridge above a wide floor: no contact anywhere


def _side_of_ridge(xy: np.ndarray) -> np.ndarray:
    """Signed distance of points (..., 2) from the ridge line through the origin."""
    return xy @ np.array([-np.sin(PHI), np.cos(PHI)])


def _clip(polygon: list[np.ndarray], keep_positive: bool) -> list[np.ndarray]:
    """A convex polygon (xy corners) cut by the ridge line (Sutherland-Hodgman, one edge)."""
    out = []
    for a, b in zip(polygon, polygon[1:] + polygon[:1]):
        sa, sb = _side_of_ridge(a), _side_of_ridge(b)
        if (sa >= 0) == keep_positive:
            out.append(a)
        if (sa >= 0) != (sb >= 0):
            out.append(a + (b - a) * (sa / (sa - sb)))
    return out


def roof() -> TriangleSoup:
    """The unit-square UV chart lifted onto two planes that meet at a ridge at PHI to the
    texel grid: accessibility (1 + n_z) / 2 on each side (the floor occludes below the
    horizon), 0.93 and 0.67: a jump inside the texels along the ridge, no contact."""
    square = [np.array(c, float) for c in ((-1, -1), (1, -1), (1, 1), (-1, 1))]
    tris = []
    for keep in (True, False):
        poly = _clip(square, keep)
        for k in range(1, len(poly) - 1):
            tris.append([poly[0], poly[k], poly[k + 1]])
    xy = np.array(tris)
    s = _side_of_ridge(xy)
    z = HEIGHT - np.where(s >= 0, s * np.tan(SLOPES[0]), -s * np.tan(SLOPES[1]))
    pos = np.concatenate([xy, z[..., None]], axis=2)
    flip = np.cross(pos[:, 1] - pos[:, 0], pos[:, 2] - pos[:, 0])[:, 2] < 0  # all facing up
    pos[flip] = pos[flip][:, ::-1]
    xy[flip] = xy[flip][:, ::-1]
    return TriangleSoup(pos, (xy + 1.0) / 2.0, name="roof")


def side_fractions(surface: TriangleSoup, samples: int = 64) -> np.ndarray:
    """(SIZE, SIZE) fraction of each texel on the gentle side of the ridge (8 x 8 points)."""
    texel, face, bary = texel_sample_points(surface.uvs, SIZE, samples)
    xy = np.einsum("mk,mkd->md", bary, surface.positions[face])[:, :2]
    side = np.bincount(texel, weights=_side_of_ridge(xy) > 0, minlength=SIZE * SIZE)
    return (side / np.maximum(np.bincount(texel, minlength=SIZE * SIZE), 1)).reshape(SIZE, SIZE)


def bake_floor(method: str, samples: int):
    surface = roof()
    settings = BakeSettings(size=SIZE, directions=DIRECTIONS, method=method, margin=0, samples_per_texel=samples,
                            normals="face")
    return surface, bake(surface, [scenes.grid_plane(400.0, 4, name="floor")], settings, use_cache=False)


@pytest.fixture(scope="module")
def truth(gpu_context):
    """(each texel's mean: the two sides' values (the reference's, away from the ridge)
    mixed by the texel's area on each side from 64 points, the edge texels)."""
    surface, res = bake_floor("reference", 1)
    fraction = side_fractions(surface)
    edge = (fraction > 0.0) & (fraction < 1.0)
    gentle, steep = (float(np.median(res.ao[(fraction == v) & res.covered])) for v in (1.0, 0.0))
    assert edge.sum() > 40
    return fraction * gentle + (1.0 - fraction) * steep, edge


def edge_rmse(ao: np.ndarray, truth) -> float:
    ref, edge = truth
    e = ao[edge].astype(np.float64) - ref[edge]
    return float(np.sqrt((e * e).mean()))


def test_the_roof_jumps_as_expected(truth):
    ref, edge = truth
    for value, slope in zip((ref[~edge].max(), ref[~edge].min()), SLOPES):
        assert abs(value - (1.0 + np.cos(slope)) / 2.0) < 0.02, (value, slope)


def test_sub_texel_points_are_a_stratified_grid():
    plane = scenes.grid_plane(2.0, 1)
    texel, face, bary = texel_sample_points(plane.uvs, 4, 4)
    assert np.bincount(texel).tolist() == [4] * 16
    uv = np.einsum("mk,mkd->md", bary, plane.uvs[face])
    first = uv[texel == 0] * 4  # texel (0, 0) in texel units
    # Points on the plane's diagonal are moved SAMPLE_INSET inside their face (a face spans
    # 4 texels here), so the grid holds to within that inset and no more.
    inset = 4 * SAMPLE_INSET
    grid = np.array([[x, y] for x in (0.25, 0.75) for y in (0.25, 0.75)])
    nearest = np.abs(first[:, None, :] - grid[None]).max(axis=2)
    assert sorted(nearest.argmin(axis=1).tolist()) == [0, 1, 2, 3]
    assert nearest.min(axis=1).max() <= inset, nearest.min(axis=1)
    with pytest.raises(ValueError, match="square"):
        sub_texel_grid(8)


@pytest.mark.parametrize("method", ["gather", "reference"])
def test_sub_texel_samples_cut_the_edge_error(truth, method):
    """Along the ridge the centre sample errs by a good part of the jump; 16 samples per
    texel remove most of it (measured 0.069 -> 0.006; 4 samples 0.020)."""
    _floor, one = bake_floor(method, 1)
    _floor, many = bake_floor(method, 16)
    before, after = edge_rmse(one.ao, truth), edge_rmse(many.ao, truth)
    assert after < 0.25 * before, (before, after)


def test_four_samples_already_halve_it(truth):
    _floor, one = bake_floor("gather", 1)
    _floor, four = bake_floor("gather", 4)
    assert edge_rmse(four.ao, truth) < 0.6 * edge_rmse(one.ao, truth)


def test_the_scatter_takes_more_light_view_pixels_per_texel(truth):
    """The scatter averages each texel's area already; its anti-aliasing is a finer
    light-view grid (pixel side / sqrt(samples)): measured 0.024 -> 0.014 at 16."""
    _floor, one = bake_floor("scatter", 1)
    _floor, many = bake_floor("scatter", 16)
    assert many.stats["pixel_size_world"] == pytest.approx(one.stats["pixel_size_world"] / 4.0, rel=1e-6)
    assert edge_rmse(many.ao, truth) < 0.8 * edge_rmse(one.ao, truth)


def test_the_uploaded_texel_list_equals_the_gpu_raster(gpu_context, monkeypatch):
    """At one sample per texel the gather lists texel centres with a UV-space raster on the
    GPU; the uploaded list (core/bake/receivers.py) holds the same receivers."""
    import hao_addon.gpu.bake_gather as gather

    _floor, gpu_list = bake_floor("gather", 1)
    monkeypatch.setattr(gather, "GPU_TEXEL_LIST", False)
    _floor, uploaded = bake_floor("gather", 1)
    assert uploaded.stats["cpu_receivers"] is True and gpu_list.stats["cpu_receivers"] is False
    assert (uploaded.covered == gpu_list.covered).all()
    np.testing.assert_allclose(uploaded.ao, gpu_list.ao, atol=1e-6)


def test_area_points_are_uniform_over_the_covered_part_of_their_texel():
    """The scatter's floor check draws points of a texel's area (uv_raster.texel_area_points):
    each lies in its own texel, inside a triangle, and over many draws they spread uniformly
    over the part the triangles cover (a texel cut by a diagonal: only its lower half)."""
    from hao_addon.core.bake.uv_raster import texel_area_points
    half = np.array([[[0.0, 0.0], [1.0, 0.0], [1.0, 1.0]]])  # below the diagonal v = u
    size, cells = 4, np.array([1, 5, 10, 15])  # (1, 0) wholly covered; the others cut in two
    points, missed = [], 0
    for seed in range(400):
        face, bary = texel_area_points(half, size, cells, seed, points=2)
        assert (face[0] == 0).all() and set(face.ravel().tolist()) <= {0, -1}
        if (face < 0).any():  # all 8 tries of a cut texel missed: 1 in 256 per texel
            missed += int((face < 0).sum())
            continue
        points.extend(np.einsum("nk,nkd->nd", bary[:, j], half[face[:, j]]) * size for j in range(2))
    assert missed <= 3 * 400 * 2 * 3 / 256
    points = np.stack(points)  # (draws, cells, 2) in texel units
    assert (np.floor(points[..., 0]) == cells % size).all() and (np.floor(points[..., 1]) == cells // size).all()
    local = points - np.floor(points)
    assert (local[:, 1:, 1] <= local[:, 1:, 0] + 1e-9).all()  # the cut texels: below their diagonal
    n = len(points)
    np.testing.assert_allclose(local[:, 0].mean(axis=0), [0.5, 0.5], atol=4 * np.sqrt(1 / 12 / n))
    # Uniform over the lower triangle of the unit square: mean (2/3, 1/3).
    np.testing.assert_allclose(local[:, 1:].mean(axis=0), [[2 / 3, 1 / 3]] * 3, atol=4 * np.sqrt(1 / 18 / n))


def test_area_points_are_stratified_in_a_texel_covered_whole():
    """In a wholly covered texel, texel_area_points puts each of 4 points in a quarter of its
    own (uv_raster.area_strata), so their mean varies less than 4 independent uniform points'
    (variance 1/12/4 = 1/48 per axis; stratified in 2 x 2 cells: 1/192). The mixture stays
    uniform: the points' mean is the texel's centre."""
    from hao_addon.core.bake.uv_raster import texel_area_points
    whole = np.array([[[0.0, 0.0], [1.0, 0.0], [1.0, 1.0]], [[0.0, 0.0], [1.0, 1.0], [0.0, 1.0]]])
    size, cells, draws = 2, np.array([0, 1, 2, 3]), 300
    means = []
    for seed in range(draws):
        face, bary = texel_area_points(whole, size, cells, seed, points=4)
        assert (face >= 0).all()
        xy = np.einsum("npk,npkd->npd", bary, whole[face]) * size
        local = xy - np.floor(xy)
        quarter = (local[..., 0] >= 0.5).astype(int) + 2 * (local[..., 1] >= 0.5)
        assert (np.sort(quarter, axis=1) == [0, 1, 2, 3]).all()  # one point a quarter
        means.append(local.mean(axis=1))
    means = np.concatenate(means)  # (draws * cells, 2)
    assert means.var(axis=0).max() < 1.5 / 192  # independent points: 1/48 = 4/192
    np.testing.assert_allclose(means.mean(axis=0), [0.5, 0.5], atol=4 * np.sqrt(1 / 192 / len(means)))
