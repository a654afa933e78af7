# SPDX-License-Identifier: GPL-3.0-or-later
"""Pure math of the baker: direction sets, kernels, normalization, views, seams, file IO."""
from __future__ import annotations

import struct
import zlib

import numpy as np
import pytest

from hao_addon.core import directions, kernels, scenes
from hao_addon.core.bake import normalization, seams, views
from hao_addon.core.geometry import face_normals_areas, uv_areas
from hao_addon.core.imageio import exr32_bytes, png16_bytes
from hao_addon.core.bake.settings import BakeSettings


def test_fibonacci_sphere_is_unit_balanced_and_deterministic():
    d = directions.bake_directions(1024, seed=3)
    assert d.shape == (1024, 3)
    np.testing.assert_allclose(np.linalg.norm(d, axis=1), 1.0, atol=1e-12)
    # Equal-area cells: the centroid of the set is at the origin to O(1/D).
    assert np.linalg.norm(d.mean(axis=0)) < 2.0 / 1024
    np.testing.assert_array_equal(d, directions.bake_directions(1024, seed=3))
    assert not np.allclose(d, directions.bake_directions(1024, seed=4))


@pytest.mark.parametrize("count", [64, 256, 4096])
def test_hemisphere_cosine_sum_approaches_quarter(count):
    """sum_d max(w_d . n, 0) -> D/4 for any n (the integral of cos over the hemisphere is pi,
    the sphere's area 4 pi); the Fibonacci set's error shrinks faster than MC's 1/sqrt(D)."""
    d = directions.bake_directions(count, seed=0)
    n = directions.bake_directions(200, seed=99)
    s = normalization.face_normalizers(n, d, "cosine")
    rel = np.abs(s / (count / 4.0) - 1.0)
    assert rel.max() < 2.0 / np.sqrt(count)  # a random set would need ~ 1.7 / sqrt(D) at 3 sigma
    u = normalization.face_normalizers(n, d, "uniform")
    assert np.abs(u / (count / 2.0) - 1.0).max() < 3.0 / np.sqrt(count)


def test_face_normalizer_matches_brute_force_and_zero_normal():
    d = directions.bake_directions(100, seed=1)
    n = np.array([[0, 0, 1.0], [1.0, 0, 0], [0, 0, 0]])
    s = normalization.face_normalizers(n, d, "cosine", block=200)  # two faces a block
    brute = [sum(max(float(x @ nn), 0.0) for x in d) for nn in n]
    # float32 products and sums: within D rounding steps of 2^-24 (relative) of float64.
    np.testing.assert_allclose(s, brute, rtol=len(d) * 2.0**-24)
    assert s[2] == 0.0


def test_stratified_cosine_directions_have_cosine_pdf():
    rng = np.random.default_rng(0)
    d = directions.stratified_cosine_hemisphere(4096, rng)
    np.testing.assert_allclose(np.linalg.norm(d, axis=1), 1.0, atol=1e-12)
    assert (d[:, 2] >= 0).all()
    # E[cos theta] under the pdf cos/pi is 2/3; stratification makes it tight.
    assert abs(d[:, 2].mean() - 2.0 / 3.0) < 2e-3


def test_frames_are_orthonormal_even_at_minus_z():
    n = np.array([[0, 0, 1.0], [0, 0, -1.0], [1.0, 0, 0], [0.6, 0.0, 0.8]])
    f = directions.frame_from_normal(n)
    for m in f:
        np.testing.assert_allclose(m @ m.T, np.eye(3), atol=1e-12)
    np.testing.assert_allclose(f[:, 2], n)


def test_wendland_kernel_shape():
    h = 2.0
    t = np.linspace(0, 3, 301)
    w = kernels.wendland(t, h)
    assert w[0] == 1.0 and np.all(w[t >= h] == 0.0)
    assert np.all(np.diff(w) <= 1e-15)  # monotone
    # C2 at the support's end: w, w' and w'' vanish at t = h.
    eps = 1e-4
    for k in (0, 1, 2):
        val = np.diff(kernels.wendland(np.array([h - 2 * eps, h - eps, h]), h), n=k)[-1] / eps**k
        assert abs(val) < 1e-3
    with pytest.raises(ValueError):
        kernels.wendland(t, 0.0)


def test_occlusion_weight_definitions():
    t = np.array([0.5, 1.5, np.inf])
    np.testing.assert_array_equal(kernels.occlusion_weight(t, 0.0, "wendland"), [1, 1, 0])
    np.testing.assert_array_equal(kernels.occlusion_weight(t, 1.0, "none"), [1, 0, 0])
    np.testing.assert_allclose(kernels.occlusion_weight(t, 1.0, "wendland"), [kernels.wendland(0.5, 1.0), 0, 0])


def test_views_map_target_into_clip_box_with_counter_clockwise_front_faces():
    rng = np.random.default_rng(2)
    pts = rng.normal(size=(50, 3))
    omega = np.array([0.3, -0.5, 0.81])
    omega /= np.linalg.norm(omega)
    v = views.fit_view(omega, pts, None, 0.05, np.array([0.3, 0.7]), 4096)
    clip = np.c_[pts, np.ones(len(pts))] @ v.matrix.T.astype(np.float64)
    assert np.all(np.abs(clip[:, :3]) <= 1.0 + 1e-6)
    # Square pixels of the requested size.
    sx, sy = (np.linalg.norm(v.matrix[k, :3].astype(np.float64)) for k in (0, 1))
    assert abs(2.0 / sx / v.width - 0.05) < 1e-5 and abs(2.0 / sy / v.height - 0.05) < 1e-5
    # A triangle facing the light is counter-clockwise in NDC, and nearer the light is smaller depth.
    basis = views.light_basis(omega)
    tri = np.array([[0, 0, 0], basis[0], basis[1]]) @ np.eye(3)
    ndc = (np.c_[tri, np.ones(3)] @ v.matrix.T.astype(np.float64))[:, :2]
    e1, e2 = ndc[1] - ndc[0], ndc[2] - ndc[0]
    area = e1[0] * e2[1] - e1[1] * e2[0]  # 2-D cross product (numpy 2 has no 2-D np.cross)
    assert area > 0
    near = (np.r_[omega, 1] @ v.matrix.T)[2]
    far = (np.r_[-omega, 1] @ v.matrix.T)[2]
    assert near < far


def test_geometry_degenerate_triangles_have_zero_normal_not_nan():
    tris = np.array([[[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 0, 0], [1, 1, 1], [2, 2, 2]], [[1, 1, 1]] * 3], float)
    n, a = face_normals_areas(tris)
    assert np.isfinite(n).all() and np.isfinite(a).all()
    np.testing.assert_allclose(n[0], [0, 0, 1])
    assert a[1] == 0 and a[2] == 0 and not n[1].any()
    assert uv_areas(np.zeros((1, 3, 2)))[0] == 0.0


def test_dilation_fills_rings_with_neighbour_means():
    v = np.zeros((7, 7), np.float32)
    m = np.zeros((7, 7), bool)
    v[3, 3], m[3, 3] = 0.5, True
    out, valid = seams.dilate(v, m, 2)
    assert valid[1:6, 1:6].all() and not valid[0].any()
    assert np.allclose(out[valid], 0.5)


def test_finalize_map_erodes_rim_and_grows_margin():
    num = np.zeros((16, 16))
    cov = np.zeros((16, 16))
    cov[4:12, 4:12] = 1.0
    cov[4, 4:12] = 0.3  # a thin rim: eroded, then refilled from inside
    num[:] = 0.8 * cov
    num[4, 4:12] = 0.0  # garbage on the rim must not survive
    ao, covered, filled = seams.finalize_map(num, cov, margin=2)
    assert not covered[4, 5] and filled[4, 5] and abs(ao[4, 5] - 0.8) < 1e-6
    assert filled[2, 6] and not filled[1, 6]
    assert ao[0, 0] == 1.0  # background


def test_png16_round_trip_and_orientation():
    img = np.linspace(0, 1, 12, dtype=np.float32).reshape(3, 4)  # row 0 = bottom
    data = png16_bytes(img)
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    w, h, depth, ctype = struct.unpack(">IIBB", data[16:26])
    assert (w, h, depth, ctype) == (4, 3, 16, 0)
    idat = data[data.index(b"IDAT") + 4:data.index(b"IEND") - 8]
    raw = np.frombuffer(zlib.decompress(idat), np.uint8).reshape(3, 9)[:, 1:]
    rows = raw.copy().view(">u2").reshape(3, 4) / 65535.0
    np.testing.assert_allclose(rows[::-1], img, atol=1 / 65535)  # file's first row = image top


def test_exr_header_and_payload():
    img = np.arange(6, dtype=np.float32).reshape(2, 3) / 7.0
    data = exr32_bytes(img)
    assert struct.unpack("<ii", data[:8]) == (20000630, 2)
    tail = np.frombuffer(data[-(8 + 12):], np.uint8)
    assert struct.unpack("<ii", tail[:8].tobytes()) == (1, 12)  # last line block: y = 1, 12 bytes
    np.testing.assert_array_equal(np.frombuffer(tail[8:].tobytes(), "<f4"), img[0])  # bottom row last


def test_settings_validation_messages():
    with pytest.raises(ValueError, match="map size"):
        BakeSettings(size=0).validated()
    with pytest.raises(ValueError, match="directions"):
        BakeSettings(directions=0).validated()
    with pytest.raises(ValueError, match="samples per texel must be one of 1, 4, 9, 16"):
        BakeSettings(samples_per_texel=5).validated()
    with pytest.raises(ValueError, match="max distance"):
        BakeSettings(max_distance=float("nan")).validated()


def test_analytic_formulas():
    assert scenes.sphere_on_plane_accessibility(1.0, 1.0) == 0.0
    np.testing.assert_allclose(scenes.sphere_on_plane_accessibility(2.0, 1.0), 1 - 1 / 8)
    np.testing.assert_allclose(scenes.wall_accessibility([0.0, 0.3], 0.0), 0.5)
    np.testing.assert_allclose(scenes.wall_accessibility([0.0, 1.0, 2.0], 1.0), [0.5, 1.0, 1.0], atol=1e-12)
    # Wendland quadrature against the step version's limit: w <= step, so A_wendland >= A_step.
    x = np.array([0.1, 0.4, 0.8])
    assert np.all(scenes.wall_accessibility(x, 1.0, "wendland") >= scenes.wall_accessibility(x, 1.0, "none"))


def test_finite_wall_form_factor_limits_and_quadrature():
    """The finite wall's contour formula: an endless wall hides half the sky (1/2 at any
    distance), a point in line with a half-endless wall's end sees a quarter hidden (3/4), a
    far wall hides nothing, and points of a 4 x 2 wall match a midpoint quadrature of Malley's
    disk (the cosine-weighted hemisphere; its own error is below 1e-4 at this grid)."""
    np.testing.assert_allclose(scenes.finite_wall_accessibility([1e-3, 0.5, 3.0], 0.0, 1e9, 1e9), 0.5, atol=1e-6)
    np.testing.assert_allclose(scenes.finite_wall_accessibility([0.5, 2.0], 0.5e9, 1e9, 1e9), 0.75, atol=1e-6)
    assert scenes.finite_wall_accessibility([1e6], 0.0, 1.0, 1.0)[0] > 1.0 - 1e-9
    x, lateral = np.array([0.05, 0.3, 1.0, 2.5, 0.7]), np.array([0.0, 0.4, -1.7, 0.9, 2.6])
    grid = 1500
    c = (np.arange(grid) + 0.5) / grid
    a, b = np.meshgrid(2.0 * c - 1.0, c, indexing="xy")  # a: sideways, b: towards the wall
    inside = a * a + b * b < 1.0
    a, b = a[inside], b[inside]
    up = np.sqrt(1.0 - a * a - b * b)
    quadrature = [1.0 - ((np.abs(yi + a * xi / b) <= 2.0) & (up * xi / b <= 2.0)).sum() * 2.0 / grid ** 2 / np.pi
                  for xi, yi in zip(x, lateral)]
    np.testing.assert_allclose(scenes.finite_wall_accessibility(x, lateral, 4.0, 2.0), quadrature, atol=3e-4)


def test_closed_surface_detection():
    from hao_addon.core.geometry import is_closed_surface
    from hao_addon.core import scenes
    torus = scenes.torus(1.0, 0.4, (0, 0, 0), 24, 12).positions
    assert is_closed_surface(torus)
    assert is_closed_surface(np.concatenate([torus, torus + 3.0]))  # separate closed parts
    assert not is_closed_surface(torus[1:])  # a hole
    assert not is_closed_surface(np.concatenate([torus[:1, ::-1], torus[1:]]))  # one flipped face
    assert not is_closed_surface(np.concatenate([torus, torus[:1]]))  # a duplicated face (fin)
    assert not is_closed_surface(scenes.grid_plane(2.0, 4).positions)  # open sheet
    assert not is_closed_surface(np.zeros((0, 3, 3)))
    assert is_closed_surface(scenes.box((0, 0, 0), (1, 2, 3)).positions)
    assert not is_closed_surface(torus[:, ::-1])  # closed but inside out: faces point in


def test_surface_holes_are_the_border_loops_of_solids():
    from hao_addon.core import scenes
    from hao_addon.core.geometry import surface_holes
    torus = scenes.torus(1.0, 0.4, (0, 0, 0), 24, 12).positions
    assert surface_holes(torus) == []
    # Two holes: one face, and a quad (face 100 and a face sharing an edge with it).
    shared = [len({tuple(p) for p in torus[100]} & {tuple(p) for p in f}) for f in torus]
    partner = next(i for i, n in enumerate(shared) if n == 2)
    holed = np.delete(torus, [0, 100, partner], axis=0)
    holes = surface_holes(holed)
    assert sorted(len(h) for h in holes) == [3, 4]
    loop_points = {tuple(p) for h in holes for p in h}
    assert loop_points == {tuple(p) for p in np.concatenate([torus[0], torus[100], torus[partner]])}
    assert surface_holes(holed[:, ::-1]) is None  # inside out
    assert surface_holes(scenes.grid_plane(2.0, 4).positions) is None  # a sheet bounds nothing
    assert surface_holes(np.concatenate([holed, holed[:1]])) is None  # a fin
    # A solid beside an inside-out solid: the total volume is positive, one part's is not.
    big = scenes.torus(3.0, 1.0, (0, 0, 9), 24, 12).positions
    assert surface_holes(np.concatenate([big, torus[:, ::-1]])) is None
    assert surface_holes(np.concatenate([big, torus])) == []
    # A curved sheet (a hemisphere's cap, fanned shut) facing inwards: None; outwards: a hole.
    dome = scenes.uv_sphere(1.0, (0, 0, 20), 24, 12).positions
    dome = dome[dome[:, :, 2].min(axis=1) >= 20.0]
    assert surface_holes(np.concatenate([big, dome])) is not None
    assert surface_holes(np.concatenate([big, dome[:, ::-1]])) is None
    # Two separate solids, one with a hole, far from the origin: still found.
    two = np.concatenate([holed, scenes.box((5, 0, 0), (6, 1, 1)).positions]) + 1e5
    assert sorted(len(h) for h in surface_holes(two)) == [3, 4]


def test_weld_matches_unique_rows():
    from hao_addon.core.geometry import weld
    rng = np.random.default_rng(3)
    pts = rng.random((500, 3)).round(1)  # many exact repeats
    first, inverse = weld(pts)
    np.testing.assert_array_equal(pts[first][inverse], pts)
    assert len(first) == len(np.unique(pts, axis=0))


def test_face_chunks_and_hole_runs_are_conservative():
    """Every face turned away from a view whose light-view box meets a hole's box (and lies
    past the hole) falls in a returned run; the runs cover far fewer faces than all."""
    from hao_addon.core import scenes
    from hao_addon.core.directions import bake_directions
    from hao_addon.core.bake.face_chunks import CHUNK_FACES, face_chunks, hole_chunk_ranges, hole_chunk_ranges_many
    from hao_addon.core.geometry import face_normals_areas, surface_holes
    from hao_addon.core.bake.views import fit_view
    torus = scenes.torus(1.0, 0.4, (0, 0, 0), 96, 48).positions
    # A 3 x 3 patch of quads cut out (quad q is faces q and q + half; quad (i, j) = 48 i + j).
    quads = np.array([48 * i + j for i in (10, 11, 12) for j in (20, 21, 22)])
    holed = np.delete(torus, np.concatenate([quads, quads + len(torus) // 2]), axis=0)
    holes = surface_holes(holed)
    assert [len(h) for h in holes] == [12]
    chunks = face_chunks(holed)
    assert np.array_equal(np.sort(chunks.order), np.arange(len(holed)))
    ordered = holed[chunks.order]
    for c, box in enumerate(chunks.boxes):  # each chunk's box holds its faces
        part = ordered[c * CHUNK_FACES:(c + 1) * CHUNK_FACES].reshape(-1, 3)
        assert (part >= box[0]).all() and (part <= box[1]).all()
    normals, _ = face_normals_areas(ordered)
    points = np.unique(holed.reshape(-1, 3), axis=0)
    drawn_total = 0
    for omega in bake_directions(32, 5):
        view = fit_view(omega, points, None, 0.01, np.zeros(2), 4096)
        runs = hole_chunk_ranges(chunks, holes, view.matrix, len(holed))
        in_run = np.zeros(len(holed), bool)
        for first, count in runs:
            in_run[first:first + count] = True
        drawn_total += in_run.sum()
        clip = ordered.reshape(-1, 3) @ view.matrix[:3, :3].T.astype(np.float64) + view.matrix[:3, 3]
        clip = clip.reshape(-1, 3, 3)
        for h in holes:
            hc = h @ view.matrix[:3, :3].T.astype(np.float64) + view.matrix[:3, 3]
            meets = ((clip[..., :2].min(axis=1) <= hc[:, :2].max(axis=0))
                     & (hc[:, :2].min(axis=0) <= clip[..., :2].max(axis=1))).all(axis=1)
            meets &= clip[..., 2].max(axis=1) >= hc[:, 2].min()
            needed = meets & (normals @ omega < 0)
            assert in_run[needed].all()
    assert drawn_total < 0.25 * 32 * len(holed)
    # Many views at once (what the gather uses) give each view's own runs.
    views = [fit_view(omega, points, None, 0.01, np.zeros(2), 4096) for omega in bake_directions(16, 6)]
    matrices = np.stack([view.matrix for view in views])
    assert hole_chunk_ranges_many(chunks, holes, matrices, len(holed)) == \
        [hole_chunk_ranges(chunks, holes, m, len(holed)) for m in matrices]


def test_written_files_get_normal_permissions_and_rgba_png_header(tmp_path):
    import os
    from hao_addon.core.imageio import write_ao_file
    umask = os.umask(0)
    os.umask(umask)
    for name, img in (("gray.png", np.full((2, 3), 0.5)), ("rgba.png", np.full((2, 3, 4), 0.25)),
                      ("rgba.exr", np.full((2, 3, 4), 0.25))):
        write_ao_file(tmp_path / name, img)
        assert (tmp_path / name).stat().st_mode & 0o777 == 0o666 & ~umask, name
    data = (tmp_path / "rgba.png").read_bytes()
    assert struct.unpack(">IIBB", data[16:26]) == (3, 2, 16, 6)  # 16-bit RGBA
    assert not list(tmp_path.glob("*.part"))


def _shifted(a: np.ndarray, dy: int, dx: int, fill) -> np.ndarray:
    out = np.full_like(a, fill)
    h, w = a.shape
    out[max(0, -dy):h - max(0, dy), max(0, -dx):w - max(0, dx)] = a[max(0, dy):h - max(0, -dy), max(0, dx):w - max(0, -dx)]
    return out


def test_margin_passes_equal_whole_image_ring_by_ring_versions():
    """grow_mask (row and column running counts) and dilate (frontier lists) against the
    plain definitions: ring by ring over whole images, every 8-neighbour shift."""
    rng = np.random.default_rng(7)
    offsets = [(dy, dx) for dy in (-1, 0, 1) for dx in (-1, 0, 1) if dy or dx]
    for shape, density, rings in (((64, 96), 0.01, 5), ((50, 40), 0.2, 3), ((33, 33), 0.0005, 40)):
        mask = rng.random(shape) < density
        mask[0, 0] = True
        values = rng.random(shape).astype(np.float32)
        grown = mask.copy()
        vals, ok = np.where(mask, values, 0.0).astype(np.float32), mask.copy()
        for _ in range(rings):
            grown = grown | np.any([_shifted(grown, dy, dx, False) for dy, dx in offsets], axis=0)
            total = np.zeros(shape, np.float32)
            count = np.zeros(shape, np.float32)
            for dy, dx in offsets:
                m = _shifted(ok, dy, dx, False)
                total += np.where(m, _shifted(vals, dy, dx, 0.0), np.float32(0.0))
                count += m
            new = ~ok & (count > 0)
            vals = np.where(new, total / np.maximum(count, 1), vals)
            ok = ok | new
        np.testing.assert_array_equal(seams.grow_mask(mask, rings), grown)
        out, valid = seams.dilate(values, mask, rings)
        np.testing.assert_array_equal(valid, ok)
        np.testing.assert_array_equal(out[valid], vals[valid])


def test_normal_bin_cones_hold_every_face_a_view_can_face():
    """A batch of views tests only the bins whose cone reaches one of their hemispheres: every
    face with n . omega > 0 for some omega of the batch must be in such a bin."""
    from hao_addon.core.directions import bake_directions
    from hao_addon.core.bake.normal_bins import BIN_COUNT, bin_cones, bins_facing, normal_bins, proximity_order
    rng = np.random.default_rng(11)
    normals = rng.normal(size=(20000, 3))
    normals[:2000] = [0.0, 0.0, 1.0]  # many identical normals: a zero-width cone
    normals[2000:2010] = 0.0  # degenerate faces: unused
    length = np.linalg.norm(normals, axis=1, keepdims=True)
    normals = np.divide(normals, length, out=np.zeros_like(normals), where=length > 0)
    used = length[:, 0] > 0
    bins = normal_bins(normals)
    assert bins.min() >= 0 and bins.max() < BIN_COUNT
    axis, threshold = bin_cones(normals, bins, used)
    directions = bake_directions(64, 2)
    order = proximity_order(directions)
    assert np.array_equal(np.sort(order), np.arange(64))
    skipped = 0
    for start in range(0, 64, 4):
        omegas = directions[order[start:start + 4]]
        needed = bins_facing(axis, threshold, omegas)
        facing = used & ((normals @ omegas.T) > 0.0).any(axis=1)
        assert needed[bins[facing]].all()
        skipped += (~needed[bins[used]]).sum()
    assert skipped > 0.1 * 16 * used.sum()  # nearby directions per batch: bins are skipped (19 % here)


def test_octahedral_cell_cones_hold_every_normal_of_their_cell():
    """Smooth-shaded gather entries are binned by their own shading normal and skipped by their
    cell's cone (normal_bins.cell_cones): every unit vector, including those on the cells'
    edges, the axes and the equator fold, lies within its bin's cone; the cones are narrow."""
    from hao_addon.core.bake.normal_bins import OCT_SIDE, cell_cones, normal_bins, octahedral_decode
    rng = np.random.default_rng(5)
    normals = rng.normal(size=(400_000, 3))
    # Points on cell edges and on the fold |x| + |y| = 1 of the octahedral map.
    edge = np.round(rng.uniform(-1, 1, size=(50_000, 2)) * OCT_SIDE / 2) / (OCT_SIDE / 2)
    free = rng.uniform(-1, 1, size=(50_000, 2))
    on_edges = np.concatenate([np.stack([edge[:, 0], free[:, 1]], 1), np.stack([free[:, 0], edge[:, 1]], 1)])
    fold = rng.uniform(-1, 1, size=50_000)
    on_fold = np.stack([fold, (1.0 - np.abs(fold)) * rng.choice([-1.0, 1.0], 50_000)], 1)
    normals = np.concatenate([normals / np.linalg.norm(normals, axis=1, keepdims=True), octahedral_decode(on_edges),
                              octahedral_decode(on_fold), np.eye(3), -np.eye(3)])
    axis, threshold = cell_cones()
    cos_half = np.sqrt(1.0 - threshold**2)
    bins = normal_bins(normals)
    assert (np.einsum("nd,nd->n", normals, axis[bins]) >= cos_half[bins]).all()
    assert np.degrees(np.arccos(cos_half)).max() < 16.0  # 16 x 16 cells: at most ~15 degrees


def test_face_bins_draw_every_face_turned_towards_the_light():
    """The gather's depth maps draw only the bins' runs FaceBins.runs gives for the light:
    every face with n . omega > 0 is in one, and about half the faces are left out."""
    from hao_addon.core.bake.normal_bins import FaceBins
    from hao_addon.core.directions import bake_directions
    rng = np.random.default_rng(3)
    normals = rng.normal(size=(30_000, 3))
    normals[:10] = 0.0  # degenerate faces stay in every run
    length = np.linalg.norm(normals, axis=1, keepdims=True)
    normals = np.divide(normals, length, out=np.zeros_like(normals), where=length > 0)
    bins = FaceBins.of(normals)
    position = np.empty(len(normals), np.int64)
    position[bins.order] = np.arange(len(normals))
    left_out = 0
    for omega in bake_directions(32, 2):
        drawn = np.zeros(len(normals), bool)
        for first, end in bins.runs(omega):
            drawn[first:end] = True
        assert drawn[position[normals @ omega > 0.0]].all()
        assert drawn[position[:10]].all()
        left_out += (~drawn).sum()
    assert left_out > 0.35 * 32 * len(normals)


def test_view_fit_cell_corners_match_the_row_wise_unique():
    """cell_corners packs each cell into one int64 for a fast unique: the same corners as by rows."""
    from hao_addon.core.bake.views import cell_corners
    points = np.random.default_rng(2).normal(size=(20_000, 3)) * 0.4
    cells = np.unique(np.floor(points / 0.01).astype(np.int64), axis=0)
    offsets = np.array([[i, j, k] for i in (0, 1) for j in (0, 1) for k in (0, 1)])
    np.testing.assert_array_equal(cell_corners(points, 0.01), ((cells[:, None, :] + offsets[None]) * 0.01).reshape(-1, 3))


def test_texel_sums_normalize_each_receiver_by_its_own_weight_sum():
    """Every lit receiver weighs 1 in its texel whatever its weight scale (the gather's and
    the reference's exact normalization): texel 0 holds receivers of ratio 0.2 and 0.8 with
    weight sums 10 and 1000, texel 1 one of ratio 0.5 and one no direction lit."""
    from hao_addon.core.bake.estimators import AMBIENT_OCCLUSION, texel_sums

    texel = np.array([0, 0, 1, 1])
    sums = np.array([[2.0, 10.0], [800.0, 1000.0], [3.0, 6.0], [0.0, 0.0]])
    out = texel_sums(texel, sums, (2, 2))
    numerator, weight = AMBIENT_OCCLUSION.ratio(out)
    np.testing.assert_allclose(numerator.ravel(), [1.0, 0.5, 0.0, 0.0])
    np.testing.assert_allclose(weight.ravel(), [2.0, 1.0, 0.0, 0.0])
    scaled = texel_sums(texel, sums * np.array([7.0, 0.01, 3.0, 5.0])[:, None], (2, 2))
    np.testing.assert_allclose(scaled, out)


def test_plane_slope_is_the_clip_space_normals_slope():
    """The gather's depth slope of a receiver's plane (OrthoView.plane_slope, used with
    m = M g in plane_lookup) equals the slope -n.xy / (n.z * size) of the clip-space normal
    n = M^-T g, for fitted views of every shape (non-square windows, any direction)."""
    from hao_addon.core.bake.views import fit_views
    rng = np.random.default_rng(3)
    points = rng.normal(size=(400, 3)) * [3.0, 1.0, 0.2]  # a flat, elongated cloud: uneven windows
    omegas = rng.normal(size=(12, 3))
    omegas /= np.linalg.norm(omegas, axis=1, keepdims=True)
    views = fit_views(omegas, points, [None] * 12, 0.01, rng.uniform(size=(12, 2)), 4096)
    assert len({(v.width, v.height) for v in views}) > 6
    for view in views:
        linear = view.matrix[:3, :3].astype(np.float64)
        normals = rng.normal(size=(20, 3))
        clip = normals @ np.linalg.inv(linear)  # rows: (M^-T g)^T
        expected = -clip[:, :2] / (clip[:, 2:] * [view.width, view.height])
        m = normals @ linear.T
        np.testing.assert_allclose(view.plane_slope() * m[:, :2] / m[:, 2:], expected, rtol=1e-5, atol=1e-12)


def test_surface_holes_are_remembered_by_their_corners(monkeypatch):
    """A re-bake plans the same scenes again: the holes of corners seen among the last few
    come back without being found again, read-only; other corners (one bit) are found anew."""
    from hao_addon.core import geometry, scenes
    torus = scenes.torus(1.0, 0.4, (0, 0, 0), 24, 12).positions
    holed = np.delete(torus, [0, 100], axis=0)
    first = geometry.surface_holes(holed)
    found = []
    monkeypatch.setattr(geometry, "_surface_holes", lambda *a: found.append(1) or [])
    assert geometry.surface_holes(holed.copy()) is first and found == []
    assert all(not loop.flags.writeable for loop in first)
    nudged = holed.copy()
    nudged.view(np.uint64)[5, 1, 2] ^= np.uint64(1)  # one bit of one corner
    assert geometry.surface_holes(nudged) == [] and found == [1]
    for k in range(geometry.HOLES_REMEMBERED):  # pushed out by others
        geometry.surface_holes(holed + k + 1.0)
    assert geometry.surface_holes(holed) == [] and len(found) == 2 + geometry.HOLES_REMEMBERED


def test_texel_sums_at_some_cells_are_the_whole_maps_there():
    from hao_addon.core.bake.estimators import texel_sums, texel_sums_at
    rng = np.random.default_rng(4)
    texel = rng.integers(0, 64, 500)
    sums = rng.random((500, 3))
    sums[::7, -1] = 0.0  # unlit receivers add nothing
    cells = np.array([0, 3, 17, 40, 63])
    whole = texel_sums(texel, sums, (8, 8)).reshape(-1, 3)
    np.testing.assert_allclose(texel_sums_at(texel, sums, cells), whole[cells], rtol=1e-12)
    assert texel_sums_at(texel, sums, np.zeros(0, np.int64)).shape == (0, 3)
