# SPDX-License-Identifier: GPL-3.0-or-later
"""The stated error is the whole error: the visibility floor a GPU bake measures at sampled
texels (hao_addon/floor_check.py, core/bake/error_estimate.with_floor) added to its twins, checked
against the independent truth (bench/truth.py: Embree at the bake's own sample points); the
quality presets' own caps.

Calibration bound: as tests/test_error_estimate.py, the stated RMSE within 25 % of the
measured one."""
from __future__ import annotations

import sys
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from hao_addon.bake import bake
from hao_addon.core import scenes
from hao_addon.core.bake import error_estimate as ee
from hao_addon.core.bake.settings import QUALITY_CAPS, BakeSettings
from hao_addon.core.geometry import TriangleSoup
from hao_addon.core.objfile import obj_soup

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "bench"))
CALIBRATION = 0.25


def test_with_floor_adds_the_shared_part_only():
    """A floor both replicates share adds in quadrature; parts that differ between them (they
    change with the rotation, and the twins hold them) add nothing."""
    base = ee.ErrorEstimate(0.003, 0.008, 1024)
    rng = np.random.default_rng(0)
    n = 4000
    shared = np.full(n, 0.004)
    whole = ee.with_floor(base, shared, shared, np.full(n, 0.003))
    assert whole.rmse == pytest.approx(0.005, rel=1e-6) and whole.floor_rmse == pytest.approx(0.004)
    assert whole.p99 > base.p99 and whole.floor_texels == n
    apart = ee.with_floor(base, rng.normal(0, 0.004, n), rng.normal(0, 0.004, n), np.full(n, 0.003))
    assert apart.rmse < 0.00305 and apart.floor_rmse < 0.0005
    assert ee.with_floor(base, np.zeros(0), np.zeros(0), np.zeros(0)) == base


def test_where_the_floor_is_most_of_the_error_it_sets_the_p99():
    """5 % of the texels share a floor of 0.02-0.04 and every texel's noise is what the twins
    say (p99 0.0013): the error's p99 is the floor's. The sampled texels' local RMS (0.004)
    calibrates only the noise, so that it may be noisier than the twins' own without lowering
    the floor: scaling the twins' p99 by the sample's ratio with and without the floor stated
    0.0050, 7x under (the scatter on smooth fandisk stated 0.061 under a floor p99 of 0.072)."""
    rng = np.random.default_rng(0)
    n, tail = 6000, 300
    floor = np.zeros(n)
    floor[:tail] = rng.uniform(0.02, 0.04, tail)
    base = ee.ErrorEstimate(0.0005, 0.0013, 16384)
    stated = ee.with_floor(base, floor, floor, np.full(n, 0.004))
    exact = np.percentile(np.abs(floor + rng.normal(0.0, 0.0005, n)), 99)
    assert abs(stated.p99 / exact - 1.0) < 0.05
    no_floor = ee.with_floor(base, np.zeros(n), np.zeros(n), np.full(n, 0.004))
    assert no_floor.p99 == pytest.approx(base.p99, rel=1e-6)


@pytest.mark.parametrize("seed", range(4))
def test_a_heavy_tailed_floor_keeps_its_tail_in_the_p99(seed):
    """The floor is heavy-tailed (a few texels where the shadow maps miss an occluder; the
    rocker arm at 128^2: one texel of 6949 holds a fifth of its square), and the probe's part
    that changes with the rotation sits elsewhere too. 2 % of the texels share a floor of
    0.01-0.03 (checked again along all directions: no rotation part), the others hold
    independent parts of RMS 0.0035 and no floor. The stated p99 is within 25 % of the p99 the
    exact floors give; spreading the replicates' mean instead of floor_shape's geometric mean
    stated 0.76-0.79x."""
    rng = np.random.default_rng(seed)
    n, tail = 6000, 120
    floor = np.zeros(n)
    floor[:tail] = 0.02 * rng.uniform(0.5, 1.5, tail)
    apart_a, apart_b = rng.normal(0.0, 0.0035, (2, n))
    apart_a[:tail] = apart_b[:tail] = 0.0
    base, sigma = ee.ErrorEstimate(0.001, 0.0026, 4096), np.full(n, 0.001)
    exact = ee.with_floor(base, floor, floor, sigma)
    stated = ee.with_floor(base, floor + apart_a, floor + apart_b, sigma)
    assert stated.p99 >= exact.p99 / (1.0 + CALIBRATION)
    assert stated.rmse == pytest.approx(exact.rmse, rel=0.05)


def test_a_stratified_floor_sample_weighs_each_texel_by_what_it_stands_for():
    """One texel at risk of 6400 holds a floor of 0.9, checked with 2047 random others of no
    floor: weighed by its stratum (itself alone) the floor's RMS is the population's, 0.9 /
    sqrt(6400); counted as one of the 2048 checked it would be 0.9 / sqrt(2048), 1.8x over.
    A weight for all alike gives numpy's percentile."""
    n, population = 2048, 6400
    floor = np.zeros(n)
    floor[0] = 0.9
    weight = np.full(n, (population - 1) / (n - 1))
    weight[0] = 1.0
    base = ee.ErrorEstimate(0.0005, 0.0015, 4096)
    stated = ee.with_floor(base, floor, floor, np.full(n, 0.0005), weight)
    assert stated.floor_rmse == pytest.approx(0.9 / np.sqrt(population), rel=1e-9)
    assert ee.with_floor(base, floor, floor, np.full(n, 0.0005)).floor_rmse == pytest.approx(0.9 / np.sqrt(n))
    values = np.random.default_rng(0).random(1001)
    assert ee.weighted_percentile(values, np.full(1001, 3.0), 99) == pytest.approx(np.percentile(values, 99))


class _RiskyBaker:
    """A stand-in baker for floor_sample: every covered texel its own point; `risky` at risk."""
    FRESH_DRAWS = False

    def __init__(self, risky):
        self.risky = np.asarray(risky, np.int64)

    def at_risk_cells(self):
        return self.risky

    def sample_receivers(self, cells, draw=0):
        from hao_addon.core.bake.receivers import Receivers
        k = len(cells)
        return Receivers(np.zeros((k, 3)), np.tile([0.0, 0.0, 1.0], (k, 1)), np.tile([0.0, 0.0, 1.0], (k, 1)),
                         np.ones(k), np.asarray(cells, np.int64))


@pytest.mark.parametrize("seed", range(3))
def test_the_floor_check_checks_every_texel_at_risk(seed):
    """Texels at risk (the gather's with a shading normal against its face) are each checked,
    up to a quarter of the sample, whatever the seed: the bunny's one such texel at 128^2 (0.92
    off) was checked by chance at 1024 directions and missed at 4096 (stated 0.28x)."""
    from hao_addon.floor_check import floor_sample, floor_texel_count
    covered = np.ones((128, 128), bool)
    covered[:, :10] = False
    wanted = floor_texel_count(1024)
    sample = floor_sample("gather", covered, _RiskyBaker([3, 15819, 16020]), 1024, seed)
    assert len(sample.cells) == wanted and sample.cells[sample.at_risk].tolist() == [15819, 16020]
    assert sample.population == (2, int(covered.sum()) - 2)  # texel 3 is not covered
    weights = sample.weights(np.ones(len(sample.cells), bool))
    assert np.all(weights[sample.at_risk] == 1.0) and weights.sum() == pytest.approx(covered.sum())
    many = floor_sample("gather", covered, _RiskyBaker(np.flatnonzero(covered.ravel())[::7]), 1024, seed)
    assert many.at_risk.sum() == wanted // 4 and len(many.cells) == wanted


def test_the_gather_finds_its_texels_at_risk(gpu_context, monkeypatch):
    """Two quads of a plane shaded with normals that point below it (0.6, 0, -0.8): the gather
    finds their 32 texels at risk (as the CPU raster's receivers have them), and its bake's
    floor check checks each."""
    import hao_addon.bake as bake_module
    from hao_addon.core.bake.plan import make_plan_steps
    from hao_addon.core.bake.targets import as_bake_target
    from hao_addon.core.steps import drain
    from hao_addon.floor_check import floor_sample
    plane = scenes.grid_plane(2.0, 8)
    normals = np.tile([0.0, 0.0, 1.0], (len(plane.positions), 3, 1))
    for cell in (10, 37):
        normals[[cell, cell + 64]] = [0.6, 0.0, -0.8]
    plane = replace(plane, normals=normals)
    settings = BakeSettings(size=32, margin=0, normals="mesh", method="gather", directions=256)
    cpu = drain(make_plan_steps(as_bake_target(plane, "image", None, None), [], settings)).receivers()
    expected = np.unique(cpu.texel[np.einsum("ij,ij->i", cpu.shading, cpu.geometric) < 0.0])
    samples = []
    monkeypatch.setattr(bake_module, "floor_sample", lambda *a: samples.append(floor_sample(*a)) or samples[-1])
    bake(plane, [], settings, use_cache=False)
    assert len(expected) == 32 and samples[0].cells[samples[0].at_risk].tolist() == expected.tolist()
    assert samples[0].population[0] == 32


@pytest.mark.parametrize("method", ["gather", "scatter"])
def test_a_probe_snapshot_is_the_partial_map_at_its_cells(gpu_context, method):
    """What the floor check keeps of a partial map (the gather: each entry's value, summed per
    texel only at the checked texels) is the partial map at those texels, four sample points a
    texel (several entries each) and texels no direction lit (NaN) included."""
    from hao_addon.bakers import baker_for
    from hao_addon.core.bake.plan import make_plan_steps
    from hao_addon.core.bake.probe_snapshot import MapSnapshot
    from hao_addon.core.bake.targets import as_bake_target
    from hao_addon.core.steps import drain
    from hao_addon.replicates import probe_snapshot
    spot = obj_soup(ROOT / "samples" / "spot.obj")
    settings = BakeSettings(size=48, margin=0, normals="face", method=method, directions=64,
                            samples_per_texel=4 if method == "gather" else 1)
    plan = drain(make_plan_steps(as_bake_target(spot, "image", None, None), [], settings))
    baker = baker_for(method)(plan)
    try:
        for index in range(3):
            baker.run_direction(index)
        kept = probe_snapshot(baker)
        whole = MapSnapshot.of(plan.estimator, baker.accumulated())
    finally:
        baker.free()
    cells = np.sort(np.random.default_rng(0).choice(48 * 48, size=600, replace=False))
    expected = whole.at(cells)
    assert np.isnan(expected).any() and np.isfinite(expected).sum() > 100
    np.testing.assert_allclose(kept.at(cells), expected, rtol=0, atol=1e-6)


@pytest.fixture(scope="module")
def spot_truth(gpu_context):
    """Spot, flat, 48^2: the Embree truth at the gather's own sample points (8192 rays each)."""
    from truth import bake_sample_points, truth_at
    spot = obj_soup(ROOT / "samples" / "spot.obj")
    settings = BakeSettings(size=48, margin=0, normals="face", method="gather")
    return spot, settings, truth_at(spot, [], bake_sample_points(spot, settings), rays=8192)


# Since contacts are traced exactly (hao_addon/contact_repair.py) most of the gather's floor on
# Spot at 48^2 is gone (64 of its 1029 texels, its concave creases, were traced): what the
# twins miss at 4096 directions shows. Measured: traced texels 0.0023 RMS from the truth where
# their twins state 0.0014 (direction error the two replicates share, no visibility floor);
# seed 1 states 0.88x with the floor and 0.79x without it, seed 7 0.73x (its floor estimate
# is 0). Calibrating the twins is issue 57's first item; until then these two fail, strictly.
TWINS_SHORT = pytest.mark.xfail(strict=True, reason="the twins understate the direction error at 4096 (issue 57)")


@pytest.mark.parametrize("directions, seed", [(256, 0), (4096, 0), pytest.param(4096, 1, marks=TWINS_SHORT),
                                              pytest.param(4096, 7, marks=TWINS_SHORT)])
def test_the_stated_error_is_the_whole_error_against_the_truth(spot_truth, monkeypatch, directions, seed):
    """At 4096 directions Spot's gather map at 48^2 is mostly floor (the twins alone state
    about a third of the measured RMSE); with the floor the stated RMSE is within 25 % of the
    measured one at both counts, and leaving the floor out (with_floor returning the twins'
    estimate) fails the bound at 4096. Seeds 1 and 7 stated 0.74x and 0.68x before the
    largest probe floors were checked again along all directions (floor_check.REFINED_SHARE)."""
    spot, settings, truth = spot_truth

    def measured_ratio():
        result = bake(spot, [], replace(settings, directions=directions, seed=seed), use_cache=False)
        both = result.covered & truth.covered
        error = result.ao[both] - truth.values[both]
        measured = np.sqrt(max(np.mean(error ** 2) - truth.noise ** 2, 0.0))
        return result.error.rmse / measured, result.error

    ratio, error = measured_ratio()
    assert abs(ratio - 1.0) < CALIBRATION, (ratio, error)
    assert error.floor_texels > 0 and error.floor_rmse > 0.0
    if directions == 4096:
        import hao_addon.bake as bake_module
        monkeypatch.setattr(bake_module, "with_floor", lambda error, *args: error)
        ratio_without, _ = measured_ratio()
        assert ratio_without < 1.0 - CALIBRATION, ratio_without


def test_the_reference_states_no_floor_and_the_scatter_measures_its_own(gpu_context):
    """The reference's visibility is exact: it has no floor to state. The scatter's is
    measured (abilities.floor_unchecked is empty for both GPU bakers)."""
    floor, ball = scenes.grid_plane(4.0, 4, name="floor"), scenes.uv_sphere(0.6, (0, 0, 0.6), 12, 6, name="ball")
    for method in ("reference", "scatter"):
        result = bake(floor, [ball], BakeSettings(size=16, directions=64, method=method, margin=0), use_cache=False)
        assert (result.error.floor_texels > 0) == (method == "scatter"), (method, result.error)
        assert not result.error.floor_unmeasured and "not measured" not in result.error.text()


@pytest.fixture(scope="module")
def spot_area_truth(gpu_context):
    """Spot, flat, 48^2: the Embree truth of texel-area averages (floor_bench.AREA_GRID^2
    points a texel, 8192 rays in all), what the scatter's texels are."""
    from floor_bench import area_truth
    spot = obj_soup(ROOT / "samples" / "spot.obj")
    return spot, area_truth(spot, 48, 8192, False)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_the_scatter_states_its_floor_against_the_area_truth(spot_area_truth, monkeypatch, seed):
    """Spot's scatter map at 48^2 and 4096 directions is almost all floor (measured 0.019 RMSE,
    its twins alone state 0.0015). The floor check, at random points of the texels' areas,
    states it: measured / stated 0.99-1.22 over seeds 0-4 against an 8 x 8 grid a texel
    (0.86-0.99 against 4 x 4; half the square sits in 11 of 1114 texels), within the 25 %
    calibration bound. Leaving the floor out states less than
    a fifth."""
    spot, truth = spot_area_truth
    settings = BakeSettings(size=48, margin=0, normals="face", method="scatter", directions=4096, seed=seed)

    def measured_ratio():
        result = bake(spot, [], settings, use_cache=False)
        both = result.covered & truth.covered
        error = result.ao[both] - truth.values[both]
        return np.sqrt(max(np.mean(error ** 2) - truth.noise ** 2, 0.0)) / result.error.rmse

    assert abs(measured_ratio() - 1.0) < CALIBRATION
    if seed == 0:
        import hao_addon.bake as bake_module
        monkeypatch.setattr(bake_module, "with_floor", lambda error, *args: error)
        assert measured_ratio() > 5.0


@pytest.mark.parametrize("method", ["gather", "scatter"])
def test_the_floor_check_samples_the_texels_the_error_covers(gpu_context, monkeypatch, method):
    """The floor is checked where the map holds the bake's own estimate (the texels its stated
    error covers), not at texels grown from their neighbours: the scatter's splats reach
    texels a triangle covers in part or not at all, and checking their own partial sums stated
    the rocker arm's floor at 0.0083 (128^2, flat, 1024 directions) where the map's whole error
    is 0.0065 (bench/floor_bench.py; 0.0048 stated now)."""
    import hao_addon.bake as bake_module
    spot = obj_soup(ROOT / "samples" / "spot.obj")
    given = []

    def recording(method_name, covered, *args):
        given.append(np.asarray(covered).copy())
        return floor_sample(method_name, covered, *args)

    from hao_addon.floor_check import floor_sample
    monkeypatch.setattr(bake_module, "floor_sample", recording)
    result = bake(spot, [], BakeSettings(size=48, margin=0, normals="face", method=method, directions=64),
                  use_cache=False)
    assert len(given) == 1 and result.error.floor_texels > 0
    assert np.array_equal(given[0].reshape(result.covered.shape), result.covered)


def test_presets_cap_themselves_and_a_capped_bake_says_what_it_needs(gpu_context):
    """Draft at the default Directions (256) bakes past 256 directions to its target; Custom
    stops at Directions and says how many the target needs by the measured rate."""
    assert QUALITY_CAPS["8-bit"] >= 65536 and BakeSettings(quality="draft").direction_cap == QUALITY_CAPS["draft"]
    assert BakeSettings(quality="custom", max_error=0.01, directions=300).direction_cap == 300
    floor, ball = scenes.grid_plane(4.0, 8, name="floor"), scenes.uv_sphere(0.6, (0, 0, 0.6), 24, 12, name="ball")
    settings = BakeSettings(size=32, method="reference", margin=0, quality="draft")
    assert settings.directions == 256
    draft = bake(floor, [ball], settings, use_cache=False)
    assert draft.error.directions > 256 and not draft.error.capped and draft.error.p99 <= 0.01
    capped = bake(floor, [ball], replace(settings, quality="custom", max_error=0.002, directions=128),
                  use_cache=False)
    assert capped.error.capped and capped.stats["directions_needed"] > 128
    assert any("needs about" in w and "raise Directions" in w for w in capped.stats["warnings"])


def crease_soup(size: int) -> TriangleSoup:
    """A floor (z = 0, x in [0, 1]) meeting a wall (x = 0, facing +x) at a concave right angle,
    their UV charts sharing the crease on a column of texel centres (u = 8.5 / 16 at 16^2)."""
    c = (size // 2 + 0.5) / size
    floor = [[(0, 0, 0), (1, 0, 0), (1, 1, 0)], [(0, 0, 0), (1, 1, 0), (0, 1, 0)]]
    wall = [[(0, 0, 0), (0, 1, 0), (0, 1, 1)], [(0, 0, 0), (0, 1, 1), (0, 0, 1)]]
    uv_floor = [[(c + x * (1 - c), y) for x, y, _z in tri] for tri in floor]
    uv_wall = [[(c - z * c, y) for _x, y, z in tri] for tri in wall]
    return TriangleSoup(np.array(floor + wall, float), np.array(uv_floor + uv_wall, float), name="crease")


@pytest.mark.parametrize("method", ["gather", "reference"])
def test_sample_points_lie_inside_their_face_at_a_crease(gpu_context, method):
    """Texel centres on a UV edge that is a concave crease sample a point inside their own face
    (core/bake/uv_raster.SAMPLE_INSET), not on the crease, where rounding put the GPU's points
    behind the other face: the exact truth there read 0 (every ray left through that face's back)
    where the bakes gave 0.4-0.5 (fandisk at 128^2, five texels)."""
    from truth import bake_sample_points, reference_sample_points, truth_at
    size = 16
    soup = crease_soup(size)
    settings = BakeSettings(size=size, margin=0, directions=4, method=method)
    samples = (bake_sample_points if method == "gather" else reference_sample_points)(soup, settings)
    covered, points, _shading, geometric = samples[:4]
    column = (np.flatnonzero(covered.ravel()) % size) == size // 2
    assert column.sum() >= size - 2  # the crease's texels are sampled, on one face or the other
    on_floor = geometric[:, 2] > 0.5
    inside = np.where(on_floor, points[:, 0], points[:, 2])  # distance from the crease into the face
    assert inside[column].min() > 1e-4, inside[column].min()
    truth = truth_at(soup, [], samples, rays=1024)
    ys, xs = np.nonzero(covered)
    crease = truth.values[ys[column], xs[column]]
    assert crease.min() > 0.3, crease  # about half the hemisphere is behind the other face
