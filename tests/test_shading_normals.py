# SPDX-License-Identifier: GPL-3.0-or-later
"""Bakes with the mesh's own shading normals (smooth, sharp edges, custom), against Cycles'
own AO bake of the same scene (tests/scripts/make_cycles_truths.py) and against the exact
answer where there is one; every backend (scatter, gather, reference) on each scene."""
from __future__ import annotations

import bpy
import numpy as np
import pytest

import shading_scenes as cases
from hao_addon.bake import bake
from hao_addon.blender import mesh_data
from hao_addon.core import scenes
from hao_addon.core.directions import bake_directions, replicate_sizes
from hao_addon.core.geometry import TriangleSoup, smooth_vertex_normals
from hao_addon.core.bake.settings import BakeSettings
from hao_addon.core.bake.uv_raster import interior_mask, texel_surface_samples
from hao_addon.core.bake.abilities import bakers_with

BACKENDS = bakers_with()
GPU_BACKENDS = bakers_with(gpu_only=True)


def tilted(normal_tilt_deg: float) -> TriangleSoup:
    """A lone plane (z = 0, facing +z) whose every corner normal leans by the given angle
    towards +x: what a custom-normal plane looks like."""
    plane = scenes.grid_plane(4.0, 4)
    a = np.radians(normal_tilt_deg)
    normals = np.broadcast_to([np.sin(a), 0.0, np.cos(a)], plane.positions.shape)
    return TriangleSoup(plane.positions, plane.uvs, "tilted", normals)


def terminator_expectation(tilt_deg: float, directions: int, seed: int = 0) -> float:
    """The estimator's exact value on the lone tilted plane: cosine weights about the
    shading normal, visibility 1 above the plane and 0 below it (Cycles' rule)."""
    a = np.radians(tilt_deg)
    omega = bake_directions(directions, seed)
    w = np.maximum(omega @ [np.sin(a), 0.0, np.cos(a)], 0.0)
    # The map is the mean of its two replicates' ratios (core/bake/error_estimate.py).
    parts = np.split(np.arange(directions), np.cumsum(replicate_sizes(directions))[:-1])
    return float(np.mean([(w[p] * (omega[p, 2] > 0.0)).sum() / w[p].sum() for p in parts]))


@pytest.mark.parametrize("method", BACKENDS)
def test_lone_smooth_plane_is_exactly_open_and_runs_the_flat_path(gpu_context, method):
    plane = scenes.grid_plane(4.0, 8)
    smooth = TriangleSoup(plane.positions, plane.uvs, "plane", smooth_vertex_normals(plane.positions))
    res = bake(smooth, [], BakeSettings(size=64, directions=64, method=method, margin=0), use_cache=False)
    assert res.stats["smooth_corners"] == 0  # skipped: shading equals the faces
    assert res.stats["shading_normals"] is False
    np.testing.assert_allclose(res.ao[res.covered], 1.0, atol=1e-5)


@pytest.mark.parametrize("method", BACKENDS)
@pytest.mark.parametrize("tilt", [30.0, 60.0])
def test_terminator_counts_directions_below_the_face_as_occluded(gpu_context, method, tilt):
    res = bake(tilted(tilt), [], BakeSettings(size=64, directions=256, method=method, margin=0, terminator_offset=0.0),
               use_cache=False)
    assert res.stats["shading_normals"] is True
    expected = terminator_expectation(tilt, 256)
    assert expected < 0.97  # the rule matters here: face normals or no rule would give 1
    values = res.ao[res.covered]
    # Gather and reference evaluate the same sums exactly; the scatter's per-direction texel
    # coverage varies with the light-view pixel grid (about 1 %), which the ratio weights.
    tol = 2e-3 if method == "scatter" else 1e-5
    assert abs(values.mean() - expected) < tol, (values.mean(), expected)
    assert np.abs(values - expected).max() < (0.03 if method == "scatter" else 1e-5)


@pytest.mark.parametrize("tilt", [30.0, 60.0])
def test_terminator_offset_lifts_directions_below_the_face(gpu_context, tilt):
    """With Cycles' terminator offset (core/bake/terminator.py) the lone tilted plane's
    directions just below the face start from the lifted point, and some of them pass the
    plane's edge: brighter than the rule without it, and so is the gather, within 0.008 of
    the reference (measured 0.9732 / 0.9713 at 30 degrees, 0.8707 / 0.8641 at 60: the
    gather judges the lifted point against the plane's depth at a light-view pixel centre up
    to 0.71 pixel away, and a lone plane seen from below is its own only occluder)."""
    settings = dict(size=64, directions=256, margin=0, terminator_offset=0.1)
    ref = bake(tilted(tilt), [], BakeSettings(method="reference", **settings), use_cache=False)
    gather = bake(tilted(tilt), [], BakeSettings(method="gather", **settings), use_cache=False)
    assert ref.stats["rays_lifted"] > 0 and gather.stats["terminator_lift"] is True
    ref_mean, gather_mean = ref.ao[ref.covered].mean(), gather.ao[gather.covered].mean()
    assert ref_mean > terminator_expectation(tilt, 256) + 0.03
    assert abs(gather_mean - ref_mean) < 0.008


def _bake_case(name: str, method: str, normals: str = "mesh", seed: int = 0, terminator_offset: float | None = None):
    """Bake the case through Blender's evaluated mesh (corner normals) at the truth's size
    and layout, with the case's terminator offset unless one is given: (map, truth, interior
    mask)."""
    if terminator_offset is None:
        terminator_offset = cases.terminator_offset(name)
    bpy.ops.wm.read_factory_settings(use_empty=True)
    truth = np.load(cases.truth_path(name))
    uvs = truth["uvs"].astype(np.float64)
    obj = cases.build_object(name, uvs)
    soup = mesh_data.evaluated_soup(obj, bpy.context.evaluated_depsgraph_get(), "UVMap",
                                    shading_normals=normals == "mesh")
    res = bake(soup, [], BakeSettings(size=cases.TRUTH_SIZE, directions=256, method=method, margin=0,
                                      normals=normals, seed=seed, terminator_offset=terminator_offset),
               use_cache=False)
    face, _bary, hits = texel_surface_samples(uvs, cases.TRUTH_SIZE)
    return res, truth, interior_mask(face, hits) & res.covered


def cycles_truth(truth) -> tuple[np.ndarray, np.ndarray]:
    """(the mean of Cycles' two bakes (256, 256), its noise variance per texel (256, 256)):
    two seeds differ by twice a bake's variance, their mean has half of it."""
    a, b = truth["ao"].astype(np.float64), truth["ao_seed1"].astype(np.float64)
    return 0.5 * (a + b), (a - b) ** 2 / 4.0


def _rmse_bias(a: np.ndarray, b: np.ndarray) -> tuple[float, float]:
    e = a - b
    return float(np.sqrt((e * e).mean())), float(e.mean())


# The bias the scatter's texel-area average shows against Cycles' texel-centre samples on
# these maps with face normals as well (-0.004 on Spot): not a shading-normal effect. The
# gather samples texel centres as Cycles does and must meet the target, 0.003.
BIAS_BOUND = {"gather": 0.003, "scatter": 0.006}


CYCLES_CASES = list(cases.CASES)


@pytest.mark.parametrize("name", CYCLES_CASES)
def test_gather_matches_cycles_own_shading_and_face_normals_do_not(gpu_context, name):
    """RMSE of the gather (texel-centre samples, as Cycles bakes) against Cycles' bakes (two
    seeds of 1024 samples) within the noise of both, each measured as the spread between two
    seeds (Cycles' and our direction sets). Face normals must fail the same bound: the test
    sees the difference shading normals make."""
    method = "gather"
    res, truth, mask = _bake_case(name, method)
    other, _, _ = _bake_case(name, method, seed=1)
    mean, var = cycles_truth(truth)
    t = mean[mask]
    cycles_var = float(var[mask].mean())
    ours_var = _rmse_bias(res.ao[mask], other.ao[mask])[0] ** 2 / 2.0
    bound = 1.25 * np.sqrt(cycles_var + ours_var)
    rmse, bias = _rmse_bias(res.ao[mask], t)
    assert res.stats["shading_normals"] is True and res.stats["smooth_corners"] > 0
    assert rmse <= bound, f"{name} {method}: RMSE {rmse:.4f} > noise bound {bound:.4f}"
    assert abs(bias) <= BIAS_BOUND[method], f"{name} {method}: bias {bias:.4f}"
    if name != "fandisk_sharp":  # mostly flat CAD faces: the faces' normals are its shading
        flat, _, _ = _bake_case(name, method, normals="face")
        assert flat.stats["shading_normals"] is False
        flat_rmse = _rmse_bias(flat.ao[mask], t)[0]
        assert flat_rmse > bound, f"{name} {method}: face normals pass too ({flat_rmse:.4f} <= {bound:.4f})"


@pytest.mark.parametrize("name", ["spot_smooth", "rocker_smooth", "spot_custom"])
def test_scatter_is_closer_to_cycles_with_shading_normals(gpu_context, name):
    """The scatter averages each texel's area, Cycles samples its centre: against Cycles it
    carries that difference (RMSE 0.012 on Spot, bias -0.004 with face normals too), so it
    is held to its twins on the analytic scenes above and here to: mesh shading is closer to
    Cycles than face normals, and its bias stays within BIAS_BOUND."""
    res, truth, mask = _bake_case(name, "scatter")
    flat, _, _ = _bake_case(name, "scatter", normals="face")
    t = cycles_truth(truth)[0][mask]
    rmse, bias = _rmse_bias(res.ao[mask], t)
    assert rmse < _rmse_bias(flat.ao[mask], t)[0]
    assert abs(bias) <= BIAS_BOUND["scatter"]


def test_sharp_edges_are_kept(gpu_context):
    """fandisk with Smooth by Angle at 30 degrees: the shading normals at a sharp edge are
    the faces' (no blending across it), and the map matches Cycles (test above)."""
    bpy.ops.wm.read_factory_settings(use_empty=True)
    obj = cases.build_object("fandisk_sharp", np.load(cases.truth_path("fandisk_sharp"))["uvs"].astype(np.float64))
    soup = mesh_data.evaluated_soup(obj, bpy.context.evaluated_depsgraph_get(), "UVMap")
    from hao_addon.core.geometry import face_normals_areas
    faces, _ = face_normals_areas(soup.positions)
    dots = np.einsum("fki,fi->fk", soup.normals, faces)
    # Every corner normal stays within the 30-degree sharp angle of its own face (a blend
    # across a sharp edge would lean further), and many corners are exactly flat.
    assert dots.min() > np.cos(np.radians(30.0)) - 1e-3
    assert (dots > 1.0 - 1e-6).mean() > 0.5 and (dots < 1.0 - 1e-4).any()


@pytest.mark.parametrize("method", GPU_BACKENDS)
def test_smooth_map_has_no_facets(gpu_context, method):
    """Across interior edges of a smooth mesh the map does not jump: the mean step between
    neighbouring texels on two different faces stays within the noise-level step between
    neighbours on one face; with face normals it does not (that is the faceting)."""
    def steps(ao: np.ndarray, mask: np.ndarray) -> float:
        """Mean |step| between horizontal neighbours on two faces over that on one face."""
        both = mask[:, 1:] & mask[:, :-1]
        step = np.abs(np.diff(ao.astype(np.float64), axis=1))
        return float(step[both & (face[:, 1:] != face[:, :-1])].mean() / step[both & (face[:, 1:] == face[:, :-1])].mean())

    res, truth, mask = _bake_case("spot_smooth", method)
    flat, _, _ = _bake_case("spot_smooth", method, normals="face")
    face, _b, _h = texel_surface_samples(truth["uvs"].astype(np.float64), cases.TRUTH_SIZE)
    # Cycles' map has the same ratio > 1 of its own (visibility is the true, faceted
    # surface's in both); the smooth bake may not step more than it, the flat one does.
    cycles = steps(cycles_truth(truth)[0], mask)
    ours, faceted = steps(res.ao, mask), steps(flat.ao, mask)
    assert ours <= 1.1 * cycles, (ours, cycles)
    if method == "gather":  # the scatter's tent splat blurs facets too much for this metric
        assert faceted > 1.25 * cycles, (faceted, cycles)


def test_smooth_by_angle_modifier_is_honoured():
    """Blender's Smooth by Angle modifier (geometry nodes, 4.1+): on a 16-sided cylinder at
    30 degrees the caps stay flat and the sides shade smooth in the evaluated mesh the bake
    reads. bpy 4.2's wheel cannot load the modifier's asset (the operator cancels there)."""
    bpy.ops.wm.read_factory_settings(use_empty=True)
    bpy.ops.mesh.primitive_cylinder_add(vertices=16)
    obj = bpy.context.active_object
    if bpy.ops.object.shade_auto_smooth(angle=np.radians(30.0)) != {'FINISHED'}:
        pytest.skip("this bpy cannot load the Smooth by Angle asset")
    assert [m.type for m in obj.modifiers] == ['NODES']
    soup = mesh_data.evaluated_soup(obj, bpy.context.evaluated_depsgraph_get(), None)
    from hao_addon.core.geometry import face_normals_areas
    faces, _ = face_normals_areas(soup.positions)
    dots = np.einsum("fki,fi->fk", soup.normals, faces)
    caps = np.abs(faces[:, 2]) > 0.99
    assert (dots[caps] > 1.0 - 1e-6).all()  # flat
    np.testing.assert_allclose(dots[~caps], np.cos(np.pi / 16), atol=1e-4)  # each side corner leans half a segment
