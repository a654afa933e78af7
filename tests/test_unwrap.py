# SPDX-License-Identifier: GPL-3.0-or-later
"""The xatlas unwrap at any scale and offset, its errors, and stopping it at once."""
from __future__ import annotations

import json
import os
import tempfile
import time
from pathlib import Path

import numpy as np
import pytest

from conftest import DATA
from hao_addon.core.geometry import uv_areas
from hao_addon.core.objfile import read_obj
from hao_addon.core.bake.unwrap import UnwrapError, run_unwrap, unwrap_steps, unwrap_in_process

CUBE_V = np.array([[x, y, z] for x in (0, 1) for y in (0, 1) for z in (0, 1)], float)
CUBE_T = np.array([[0, 1, 3], [0, 3, 2], [4, 6, 7], [4, 7, 5], [0, 4, 5], [0, 5, 1],
                   [2, 3, 7], [2, 7, 6], [0, 2, 6], [0, 6, 4], [1, 5, 7], [1, 7, 3]])


@pytest.fixture(scope="module")
def unit_cube_uvs():
    return run_unwrap(CUBE_V, CUBE_T, 256)


@pytest.mark.parametrize("offset", [0.0, 1e6])
@pytest.mark.parametrize("scale", [1e-6, 1e-4, 1.0, 1e4, 1e9, 1e10, 1e12])
def test_unwrap_is_scale_and_offset_invariant(unit_cube_uvs, scale, offset):
    # Before: 1e10-unit edges ran for minutes inside xatlas, 1e-4 packed no atlas at all.
    uvs = run_unwrap(CUBE_V * scale + offset, CUBE_T, 256)
    assert uvs.shape == (12, 3, 2) and np.isfinite(uvs).all()
    assert uvs.min() >= 0.0 and uvs.max() <= 1.0 and (uv_areas(uvs) > 0).all()
    np.testing.assert_allclose(uvs, unit_cube_uvs, atol=1e-6)  # xatlas sees the same unit-size copy


def test_in_process_and_child_process_unwraps_agree():
    v, t, _uv, _tuv = read_obj(DATA / "rocker-arm.obj")
    t = t[:2000]
    np.testing.assert_array_equal(unwrap_in_process(v, t, 512), run_unwrap(v, t, 512))


@pytest.mark.parametrize("vertices, triangles, message", [
    (np.zeros((3, 3)), np.array([[0, 1, 2]]), "only zero-area triangles"),
    (np.array([[0, 0, 0], [1, 1, 1], [2, 2, 2.0]]), np.array([[0, 1, 2]]), "only zero-area triangles"),
    (np.array([[0, 0, 0], [1, 0, 0], [0, np.nan, 0]]), np.array([[0, 1, 2]]), "NaN or infinite"),
    (CUBE_V, np.zeros((0, 3), int), "no triangles"),
    (CUBE_V, np.array([[0, 1, 9]]), "indices outside"),
])
def test_unwrap_refuses_what_it_cannot_unwrap(vertices, triangles, message):
    with pytest.raises(UnwrapError, match=message):
        run_unwrap(vertices, triangles, 256)


def test_closing_the_unwrap_kills_its_child_and_folder_at_once():
    v, t, _uv, _tuv = read_obj(DATA / "rocker-arm.obj")  # ~5 s of xatlas
    before = set(Path(tempfile.gettempdir()).glob("hao-unwrap-*"))
    steps = unwrap_steps(v, t, 1024)
    next(steps)
    frame_locals = steps.gi_frame.f_locals
    proc, folder = frame_locals["proc"], frame_locals["folder"]
    assert proc.poll() is None and os.path.isdir(folder)
    t0 = time.monotonic()
    steps.close()
    assert time.monotonic() - t0 < 1.0
    assert proc.poll() is not None and not os.path.exists(folder)
    assert set(Path(tempfile.gettempdir()).glob("hao-unwrap-*")) == before


# --- the atlas itself: planar charts (core/bake/charts.py) packed by xatlas --------------

BUNNY = Path(__file__).resolve().parent.parent / "bench" / "data" / "stanford-bunny.obj"
UNWRAP_BENCH = Path(__file__).resolve().parent.parent / "bench" / "results" / "unwrap_bench.json"


def helicoid(turns: float = 1.5, steps: int = 90, rings: int = 3) -> tuple[np.ndarray, np.ndarray]:
    """A spiral ramp facing up everywhere: one planar projection overlaps it with itself."""
    theta = np.linspace(0.0, turns * 2 * np.pi, steps)
    radius = np.linspace(0.3, 1.0, rings)
    th, r = np.meshgrid(theta, radius, indexing="ij")
    vertices = np.stack([r * np.cos(th), r * np.sin(th), 0.02 * th], axis=-1).reshape(-1, 3)
    index = np.arange(steps * rings).reshape(steps, rings)
    a, b, c, d = index[:-1, :-1], index[1:, :-1], index[1:, 1:], index[:-1, 1:]
    triangles = np.concatenate([np.stack([a, b, c], -1).reshape(-1, 3), np.stack([a, c, d], -1).reshape(-1, 3)])
    return vertices, triangles


def overlapping_texels(uvs: np.ndarray, size: int) -> int:
    """Texel centres strictly inside two triangles (the reference rasterizer)."""
    from hao_addon.core.bake.uv_raster import texel_surface_samples
    return int((texel_surface_samples(uvs, size)[2] > 1).sum())


@pytest.fixture(scope="module")
def bunny_atlas():
    v, t, _uv, _tuv = read_obj(BUNNY)
    return v, np.asarray(t, np.int64), run_unwrap(v, t, 256)


@pytest.mark.release_independent  # numpy and xatlas only: run on the newest release
def test_the_bunny_atlas_covers_more_texels_than_xatlas_did_and_overlaps_nowhere(bunny_atlas):
    """Issue 32: texel coverage at least that of the xatlas atlas it replaces (measured by the
    unwrap benchmark at the same size), no texel centre in two triangles at twice the size."""
    from hao_addon.core.bake.uv_raster import texel_surface_samples
    _v, t, uvs = bunny_atlas
    before = next(r for r in json.loads(UNWRAP_BENCH.read_text())["rows"]
                  if r["atlas"].startswith("xatlas") and r["size"] == 256)
    coverage = float((texel_surface_samples(uvs, 256)[2] > 0).mean())
    assert coverage >= before["coverage"], (coverage, before["coverage"])
    assert overlapping_texels(uvs, 512) == 0


@pytest.mark.release_independent  # numpy and xatlas only: run on the newest release
def test_every_chart_is_a_flat_projection_packed_at_one_scale(bunny_atlas):
    """Each face's UV area is its surface area times the cosine to its chart's direction, at
    one texel density per chart, the same for the large charts (xatlas rounds a chart's size
    to whole texels, so a chart a few texels wide gets up to 30 % more: measured; the charts
    of 500 faces or more within 8 % at 256^2); no face is seen flatter than ABSORB_MIN_COS."""
    from hao_addon.core.bake.charts import ABSORB_MIN_COS, normals_and_areas, projection_charts
    from hao_addon.core.bake.unwrap import unit_copy
    v, t, uvs = bunny_atlas
    unit = unit_copy(v, t)
    charts = projection_charts(unit, t)
    normals, areas = normals_and_areas(unit[t].astype(np.float64))
    cosine = np.einsum("ij,ij->i", normals, charts.direction[charts.face_direction])
    big = areas > np.median(areas) * 0.1
    assert cosine[big].min() >= ABSORB_MIN_COS - 1e-9
    scale = uv_areas(uvs) / (areas * cosine)
    per_chart = []
    for chart in range(charts.count):
        mine = scale[big & (charts.island == chart)]
        if len(mine) > 4:
            assert mine.std() / mine.mean() < 2e-3, (chart, mine.std() / mine.mean())
        if len(mine) >= 500:
            per_chart.append(mine.mean())
    assert len(per_chart) > 10 and max(per_chart) / min(per_chart) < 1.10
    assert 10 <= charts.count <= 400, charts.count


def test_a_chart_that_overlaps_itself_is_cut_until_nothing_overlaps():
    from hao_addon.core.bake.charts import projection_charts
    from hao_addon.core.bake.unwrap_worker import pack_charts
    v, t = helicoid()
    charts = projection_charts(v, t)
    assert charts.count == 1  # one direction sees it all...
    assert overlapping_texels(pack_charts(charts, 256, 4), 512) > 0  # ...and its projection overlaps
    uvs = run_unwrap(v, t, 256)
    assert overlapping_texels(uvs, 512) == 0


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_the_fast_overlap_check_equals_the_reference_rasterizer(seed):
    from hao_addon.core.bake.charts import overlapping_faces
    from hao_addon.core.bake.uv_raster import texel_surface_samples
    rng = np.random.default_rng(seed)
    centres = rng.random((300, 1, 2))
    uvs = np.clip(centres + rng.normal(0.0, 0.03, (300, 3, 2)), 0.0, 1.0)
    uvs[:5] = centres[:5] + rng.normal(0.0, 0.3, (5, 3, 2))  # a few large ones, some past the edges
    uvs[:5] = np.clip(uvs[:5], 0.0, 1.0)
    size = 64
    face, _bary, hits = texel_surface_samples(uvs, size)
    expected = set()
    for f in range(len(uvs)):  # the faces strictly covering a twice-covered centre
        p = uvs[f] * size - 0.5
        ys, xs = np.nonzero(hits > 1)
        a, b, c = p
        det = (b[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (b[1] - a[1])
        if abs(det) < 1e-12 or not len(xs):
            continue
        w1 = ((xs - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (ys - a[1])) / det
        w2 = ((b[0] - a[0]) * (ys - a[1]) - (xs - a[0]) * (b[1] - a[1])) / det
        if ((w1 > 1e-7) & (w2 > 1e-7) & (1 - w1 - w2 > 1e-7)).any():
            expected.add(f)
    assert expected and set(overlapping_faces(uvs, size).tolist()) == expected


@pytest.mark.release_independent  # numpy and xatlas only: run on the newest release
def test_charts_keep_their_padding_in_texels_of_the_texture(bunny_atlas):
    """The atlas is packed into exactly the texture's size, so the padding is in its texels:
    no texel within two texels of one chart is covered by another (the bake's tent and
    bilinear lookups never mix charts). Packing at xatlas' own atlas size and squeezing it
    into the texture (478^2 into 256^2 for the bunny) fails this."""
    from hao_addon.core.bake.charts import projection_charts
    from hao_addon.core.bake.unwrap import unit_copy
    from hao_addon.core.bake.uv_raster import texel_surface_samples
    v, t, uvs = bunny_atlas
    island = projection_charts(unit_copy(v, t), t).island
    face = texel_surface_samples(uvs, 256)[0]
    chart = np.where(face >= 0, island[np.maximum(face, 0)], -1)
    reach = 2
    padded = np.pad(chart, reach, constant_values=-1)
    for dy in range(-reach, reach + 1):
        for dx in range(-reach, reach + 1):
            other = padded[reach + dy:reach + dy + 256, reach + dx:reach + dx + 256]
            assert not ((chart >= 0) & (other >= 0) & (other != chart)).any(), (dx, dy)


def test_a_vertex_xatlas_misplaces_is_put_back_with_its_chart():
    """xatlas moves charts rigidly but can drop a single vertex at its atlas' corner (a UV
    sphere's pole, shared by 640 triangles, did): each chart's corners are placed by the one
    similarity fitted to the rest."""
    from hao_addon.core import scenes
    from hao_addon.core.bake.charts import projection_charts
    from hao_addon.core.bake.unwrap_worker import placed_charts
    soup = scenes.grid_plane(1.0, 8)
    vertices, index = np.unique(soup.positions.reshape(-1, 3), axis=0, return_inverse=True)
    charts = projection_charts(vertices, index.reshape(-1, 3))
    assert charts.count == 1
    angle, scale, offset = 0.7, 0.3, np.array([0.2, 0.1])
    rotate = np.array([[np.cos(angle), -np.sin(angle)], [np.sin(angle), np.cos(angle)]]) * [[1.0, -1.0]]  # mirrored
    exact = (charts.uvs - charts.uvs.reshape(-1, 2).min(axis=0)) @ rotate.T * scale + offset
    broken = exact.copy()
    broken[charts.uv_vertex == charts.uv_vertex[5, 1]] = [0.001, 0.001]  # one vertex, in every face it has
    np.testing.assert_allclose(placed_charts(charts, broken), exact, atol=1e-9)
