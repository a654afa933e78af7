# SPDX-License-Identifier: GPL-3.0-or-later
"""The Selected-to-Active ray casts are twins: the GPU's walk of a uniform grid
(gpu/bake_ray_cast.py over core/bake/ray_grid.py) finds what mathutils' BVH finds
(core/bake/projection.project_steps) on the same rays, and the grid lists every triangle in
every cell it touches."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from hao_addon.bakers import RAY_CASTS, ray_caster_for
from hao_addon.core import scenes
from hao_addon.core.bake import ray_grid
from hao_addon.core.steps import drain
from hao_addon.core.bake.ray_grid import build_grid
from hao_addon.core.objfile import read_obj
from hao_addon.gpu import list_inputs
from hao_addon.gpu.util import live_pass_count

ROCKER_OBJ = Path(__file__).parent / "data" / "rocker-arm.obj"


def cast_both(origins, dirs, tri, reach):
    """The CPU's cast, then the GPU's in each list form this Blender has (textures; storage
    buffers from 5.3 on: gpu/list_inputs.py)."""
    casts = [drain(ray_caster_for("cpu")(origins, dirs, tri, reach))]
    for form in list_inputs.available_forms():
        with list_inputs.using_form(form):
            casts.append(drain(ray_caster_for("gpu")(origins, dirs, tri, reach)))
    return casts


def surface_rays(tri: np.ndarray, count: int, standoff: float, seed: int = 0):
    """Rays towards random points of random triangles from `standoff` out along a jittered
    normal (what the projection casts: from a cage inwards, some grazing)."""
    rng = np.random.default_rng(seed)
    f = rng.integers(0, len(tri), count)
    p = np.einsum("mk,mkd->md", rng.dirichlet([1, 1, 1], count), tri[f])
    n = np.cross(tri[f, 1] - tri[f, 0], tri[f, 2] - tri[f, 0])
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    d = -(n + 0.5 * rng.normal(size=(count, 3)))
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    return p - d * standoff, d


def test_grid_lists_each_triangle_in_every_cell_its_box_overlaps():
    tri = scenes.uv_sphere(1.0, (3.0, -2.0, 7.0), 24, 12).positions
    grid = build_grid(tri)
    assert grid.cell_start[-1] == len(grid.triangle_index) and (np.diff(grid.cell_start) >= 0).all()
    assert 0.5 * ray_grid.CELLS_PER_TRIANGLE * len(tri) < grid.cell_count < 2 * ray_grid.CELLS_PER_TRIANGLE * len(tri)
    cell_of = np.repeat(np.arange(grid.cell_count), np.diff(grid.cell_start))
    rng = np.random.default_rng(1)
    for face in rng.integers(0, len(tri), 20):
        points = np.einsum("mk,kd->md", rng.dirichlet([1, 1, 1], 200), tri[face])
        cells = np.floor(grid.to_local(points)).astype(int)
        ids = (cells[:, 2] * grid.dims[1] + cells[:, 1]) * grid.dims[0] + cells[:, 0]
        assert set(ids) <= set(cell_of[grid.triangle_index == face])
    np.testing.assert_allclose(grid.local_triangles, grid.to_local(tri.reshape(-1, 3)).reshape(tri.shape), atol=1e-5)


def test_flat_mesh_gets_one_layer_and_bounded_cells():
    """A plane has no extent along z: one layer of cells; a long thin strip stays within
    MAX_CELLS_PER_AXIS."""
    plane = scenes.grid_plane(10.0, 40).positions
    grid = build_grid(plane)
    assert grid.dims[2] == 1 and grid.dims.max() <= ray_grid.MAX_CELLS_PER_AXIS
    strip = plane * np.array([100.0, 0.01, 1.0])
    assert build_grid(strip).dims.max() <= ray_grid.MAX_CELLS_PER_AXIS


def test_gpu_cast_equals_cpu_cast_on_the_rocker_arm(gpu_context):
    """60k rays from 1 % of the size out, jittered up to grazing: the same face for all but
    rays through shared edges (a handful), the same point within float32 rounding (measured
    against the float64 intersection: median 2e-9 (CPU) / 1e-8 (GPU), 3-5e-5 at rays within
    0.03 degree of the triangle's plane, for both)."""
    v, t, _uv, _tu = read_obj(ROCKER_OBJ)
    tri = v[t]
    size = float(np.ptp(v, axis=0).max())
    origins, dirs = surface_rays(tri, 60_000, 0.01 * size)
    passes = live_pass_count()
    (cf, cb), *gpu_casts = cast_both(origins, dirs, tri, 0.0)
    assert live_pass_count() == passes and len(gpu_casts) == len(list_inputs.available_forms())
    assert (cf >= 0).mean() > 0.95
    for gf, gb in gpu_casts:
        same = cf == gf
        assert same.mean() > 0.9995, f"{(~same).sum()} rays differ"
        pc = np.einsum("mk,mkd->md", cb[same & (cf >= 0)], tri[cf[same & (cf >= 0)]])
        pg = np.einsum("mk,mkd->md", gb[same & (gf >= 0)], tri[gf[same & (gf >= 0)]])
        gap = np.linalg.norm(pc - pg, axis=1)
        assert np.quantile(gap, 0.999) < 1e-6 * size and gap.max() < 1e-4 * size
    for gf, gb in gpu_casts[1:]:  # the forms differ in how the lists are read, not in what is computed
        np.testing.assert_array_equal(gf, gpu_casts[0][0])
        np.testing.assert_array_equal(gb, gpu_casts[0][1])


def test_gpu_cast_equals_cpu_cast_from_outside_and_within_a_max_distance(gpu_context):
    """Rays that start outside the grid, long misses across it, and a max ray distance that
    cuts some hits: the same faces and misses."""
    tri = np.concatenate([scenes.uv_sphere(1.0, (0, 0, 0), 32, 16).positions,
                          scenes.grid_plane(6.0, 12, z=-1.5).positions])
    rng = np.random.default_rng(4)
    origins = rng.uniform(-8, 8, size=(20_000, 3))
    aim = rng.uniform(-2, 2, size=(20_000, 3))
    dirs = aim - origins
    dirs /= np.linalg.norm(dirs, axis=1, keepdims=True)
    dirs[::97] = 0.0  # zero directions find nothing
    for reach in (0.0, 6.0):
        (cf, _), *gpu_casts = cast_both(origins, dirs, tri, reach)
        assert 0.2 < (cf >= 0).mean() < 0.9 and (cf[::97] < 0).all()
        for gf, _gb in gpu_casts:
            assert (gf[::97] < 0).all() and (cf == gf).mean() > 0.9995


@pytest.mark.parametrize("cast_name", RAY_CASTS)
def test_no_rays_cast_nothing(gpu_context, cast_name):
    face, bary = drain(ray_caster_for(cast_name)(np.zeros((0, 3)), np.zeros((0, 3)),
                                                  scenes.grid_plane(1.0, 1).positions, 0.0))
    assert face.shape == (0,) and bary.shape == (0, 3)


def test_storage_buffers_exist_where_blender_has_them_and_textures_stay_chosen(gpu_context):
    """Blender 5.3's storage buffers (compat.storage_buffers) are a list form there (cast above
    against the CPU); the passes keep textures, measured faster on llvmpipe (list_inputs.
    PREFERRED); on older releases textures are the only form and storage is refused."""
    import bpy

    from hao_addon import compat
    has = bpy.app.version >= (5, 3, 0)
    assert compat.storage_buffers() == has
    assert list_inputs.available_forms() == (("textures", "storage") if has else ("textures",))
    assert list_inputs.chosen_form().name == "textures"
    if has:
        with list_inputs.using_form("storage"):
            assert list_inputs.chosen_form().name == "storage"
    else:
        with pytest.raises(ValueError, match="5.3"), list_inputs.using_form("storage"):
            pass
