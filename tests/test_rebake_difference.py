# SPDX-License-Identifier: GPL-3.0-or-later
"""Re-bakes by difference (hao_addon/rebake_difference.py): the gather measures what an edit
changed only in the pixels the changed spheres project to, with the scene before the edit
drawn too, and adds that to the earlier map. Its re-baked texels must equal a whole bake of
the edited scene up to float rounding (ao and twins), over a chain of re-bakes; where it
cannot measure (the target edited, occluders that let light through, no earlier scene kept)
the cells are baked whole and the report says why. The numpy parts (the merge, the entry
blocks, the window test) are checked against direct computations."""
from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from hao_addon.bake import bake
from hao_addon.core import scenes
from hao_addon.core.bake.alpha import SoupAlpha
from hao_addon.core.bake.entry_blocks import (BLOCK_ENTRIES, BRIDGED_BLOCKS, block_order, block_runs,
                                              intersected_runs)
from hao_addon.core.bake.face_chunks import boxes_meeting_windows
from hao_addon.core.bake.settings import BakeSettings
from hao_addon.core.geometry import TriangleSoup
from hao_addon.rebake import rebake, record
from hao_addon.rebake_difference import Difference, merged_by_difference

SETTINGS = BakeSettings(size=256, directions=64, method="gather")
ROUNDING = 1e-6  # float32 sums: what a difference may differ from a whole bake by


def floor() -> TriangleSoup:
    soup = scenes.grid_plane(20.0, 32)
    return TriangleSoup(soup.positions, soup.uvs, "floor")


def balls(moves: dict | None = None, radius: float = 0.5) -> list[TriangleSoup]:
    """Four balls on the floor; moves: name -> (dx, dy, dz), or None to delete it."""
    out = []
    for name, (x, y) in {"b0": (-4, -4), "b1": (4, 4), "b2": (3.0, -2.0), "b3": (-5.0, 5.0)}.items():
        shift = (moves or {}).get(name, (0.0, 0.0, 0.0))
        if shift is not None:
            out.append(scenes.uv_sphere(radius, (x + shift[0], y + shift[1], radius + shift[2]), 16, 8, name=name))
    return out


@pytest.fixture(scope="module")
def base(gpu_context):
    target, occluders = floor(), balls()
    return bake(target, occluders, SETTINGS, use_cache=False), record(target, occluders, SETTINGS)


def compare(result, report, whole) -> np.ndarray:
    """The checks of a partial re-bake against a whole bake of its scene; the re-baked mask."""
    assert not report.full
    redo = np.zeros(whole.ao.size, bool)
    redo[report.cells] = True
    redo = redo.reshape(whole.ao.shape) & whole.covered
    diff = np.abs(result.ao.astype(np.float64) - whole.ao)
    # Each cell within what it carries from earlier re-bakes (0 where it was never kept).
    carried = np.zeros(diff.shape) if result.kept_offset is None else result.kept_offset
    assert (diff[redo] <= carried[redo] + ROUNDING).all(), (diff - carried)[redo].max()
    fresh = redo & (carried == 0.0)
    assert fresh.sum() > 0 and np.abs(result.twin.astype(np.float64) - whole.twin)[fresh].max() < ROUNDING
    # The stated bound holds them too (each was under the threshold of the re-bake that kept it).
    assert carried.max() <= report.kept_bound
    kept = whole.covered & ~redo
    assert diff[kept].max(initial=0.0) <= report.kept_bound + ROUNDING
    return redo


def test_rebakes_by_difference_equal_a_whole_bake_over_a_chain(base, monkeypatch):
    """Move, move far, delete and add a ball, each from the previous re-bake: every re-baked
    texel equals a whole bake of its scene up to rounding, though the light views draw only
    about the changed balls (view_pixels) and test only the entries there (texel_tests; no
    gaps bridged on this small map)."""
    from hao_addon.core.bake import entry_blocks
    monkeypatch.setattr(entry_blocks, "BRIDGED_BLOCKS", 0)
    previous, state = base
    target = floor()
    steps = [{"b1": (0.2, 0.0, 0.0)}, {"b1": (0.2, 0.0, 0.0), "b2": (-3.0, 1.0, 0.0)},
             {"b1": (0.2, 0.0, 0.0), "b2": (-3.0, 1.0, 0.0), "b0": None}]
    scenes_ = [balls(moves) for moves in steps]
    scenes_.append(scenes_[-1] + [scenes.uv_sphere(0.3, (0.0, 0.0, 0.3), 16, 8, name="new")])
    whole_pixels, shares = previous.stats["view_pixels"], []
    for occluders in scenes_:
        result, state, report = rebake(previous, state, target, occluders, SETTINGS)
        assert report.how == "by difference", report.how
        whole = bake(target, occluders, SETTINGS, use_cache=False)
        redo = compare(result, report, whole)
        # Two maps a direction, each the box about the changed balls: 7 % of a whole bake's
        # pixels for b2 moved 3 units (the box holds both places), 1-2 % for the others.
        assert result.stats["view_pixels"] < 0.1 * whole_pixels
        tests = result.stats["texel_tests"] + result.stats["texel_tests_skipped"]
        shares.append(result.stats["texel_tests"] / tests)
        assert redo.sum() > 0
        previous = result
    # A dispatch tests the blocks any of its 8 directions' windows reach: 61 % of the entries
    # for b1 moved by 0.2, 77 % where b2's box spans 3 units.
    assert shares[0] < 0.7 and max(shares) < 0.9, shares


def test_cells_are_baked_whole_where_a_difference_cannot_be_measured(base):
    """The target edited (other light views), a card that lets light through and an earlier
    state without its scene: the cells are baked whole, the report says why, and they equal
    the whole bake bit for bit (the gather bakes a subset as its whole bake does)."""
    previous, state = base
    bumped = floor()
    positions = bumped.positions.copy()
    positions[..., 2] += 0.3 * np.exp(-((positions[..., 0] - 4.0) ** 2 + (positions[..., 1] + 4.0) ** 2))
    bumped = TriangleSoup(positions, bumped.uvs, "floor")
    card = scenes.grid_plane(1.0, 2)
    card = TriangleSoup(card.positions + np.array([2.0, 2.0, 1.0]), None, "card",
                        alpha=SoupAlpha(np.full(card.face_count, 0.5, np.float32)))
    cases = [(bumped, balls(), state, "the edit moved"), (floor(), balls() + [card], state, "let light through"),
             (floor(), balls({"b1": (0.2, 0.0, 0.0)}), replace(state, scene=None), "is not kept")]
    for target, occluders, before, why in cases:
        result, _state, report = rebake(previous, before, target, occluders, SETTINGS)
        if report.full:  # the card: Auto's choice may bake it whole; the gather was asked for
            raise AssertionError(report.why)
        assert report.how.startswith("baked whole") and why in report.how, report.how
        whole = bake(target, occluders, SETTINGS, use_cache=False)
        redo = np.zeros(whole.ao.size, bool)
        redo[report.cells] = True
        redo = redo.reshape(whole.ao.shape) & whole.covered
        assert np.array_equal(result.ao[redo], whole.ao[redo])


def test_merge_recovers_each_replicate_from_the_map_and_its_twin():
    """merged_by_difference against the sums themselves: ao = (N_a + N_b) / (W_a + W_b),
    twin = (N_a / W_a - N_b / W_b) / 2, with N changed at some cells; cells it leaves
    unchanged keep their values bit for bit."""
    rng = np.random.default_rng(3)
    k = 200
    w_a, w_b = rng.integers(1, 3, k).astype(float), rng.integers(1, 3, k).astype(float)
    n_a, n_b = rng.uniform(0, 1, k) * w_a, rng.uniform(0, 1, k) * w_b
    d_a, d_b = rng.uniform(-0.3, 0.3, k) * w_a, rng.uniform(-0.3, 0.3, k) * w_b
    d_a, d_b = np.clip(n_a + d_a, 0, w_a) - n_a, np.clip(n_b + d_b, 0, w_b) - n_b
    ao = ((n_a + n_b) / (w_a + w_b)).astype(np.float32)
    twin = (0.5 * (n_a / w_a - n_b / w_b)).astype(np.float32)
    changed = np.flatnonzero(rng.uniform(size=k) < 0.5)
    values, twins = merged_by_difference(ao, twin, Difference(changed, d_a[changed], d_b[changed], w_a[changed],
                                                              w_b[changed], {}))
    n_a[changed] += d_a[changed]
    n_b[changed] += d_b[changed]
    assert np.abs(values - (n_a + n_b) / (w_a + w_b)).max() < 1e-6
    assert np.abs(twins - 0.5 * (n_a / w_a - n_b / w_b)).max() < 1e-6
    same = np.setdiff1d(np.arange(k), changed)
    assert np.array_equal(values[same], ao[same]) and np.array_equal(twins[same], twin[same])


def test_entry_blocks_keep_bins_and_order_and_runs_cover_both_lists():
    rng = np.random.default_rng(5)
    points = rng.uniform(-1, 1, (1000, 3))
    bins, cells = rng.integers(0, 4, 1000), rng.permutation(1000)
    order = block_order(points, bins, cells)
    assert (np.diff(bins[order]) >= 0).all()
    shuffled = rng.permutation(1000)  # the same entries listed in another order come out alike
    again = block_order(points[shuffled], bins[shuffled], cells[shuffled])
    assert np.array_equal(cells[order], cells[shuffled][again])
    blocks = BRIDGED_BLOCKS + 3
    count = blocks * BLOCK_ENTRIES - 5  # the last block short
    apart, bridged = np.zeros(blocks, bool), np.zeros(blocks, bool)
    apart[[0, blocks - 1]] = bridged[[0, blocks - 2]] = True  # gaps of BRIDGED_BLOCKS + 1 and BRIDGED_BLOCKS
    assert block_runs(apart, count) == [(0, BLOCK_ENTRIES), ((blocks - 1) * BLOCK_ENTRIES, count)]
    assert block_runs(bridged, count) == [(0, (blocks - 1) * BLOCK_ENTRIES)]
    a, b = [(0, 10), (20, 30), (40, 50)], [(5, 25), (45, 60)]
    assert intersected_runs(a, b) == [(5, 10), (20, 25), (45, 50)]
    covered = set().union(*(range(*r) for r in intersected_runs(a, b)))
    assert covered == set().union(*(range(*r) for r in a)) & set().union(*(range(*r) for r in b))


def test_boxes_meeting_windows_hold_every_point_that_projects_inside():
    """A point whose pixel lies in a view's window is in a box that meets it (the test is
    conservative), and a box far outside does not."""
    from hao_addon.core.bake.views import fit_views
    rng = np.random.default_rng(7)
    points = rng.uniform(-0.5, 0.5, (400, 3))
    views = fit_views(rng.normal(size=(4, 3)) / 2.0, points, [None] * 4, 0.01, rng.uniform(size=(4, 2)), 4096,
                      window_spheres=np.array([[0.1, 0.0, 0.0, 0.1]]))
    boxes = np.stack([points, points], axis=1)  # one point each
    matrices = np.stack([v.whole.matrix for v in views])
    sizes = np.array([(v.whole.width, v.whole.height) for v in views])
    windows = np.array([(*v.first, v.width, v.height) for v in views])
    meets = boxes_meeting_windows(boxes, matrices, sizes, windows)
    for k in range(len(views)):
        clip = points @ matrices[k, :2, :3].T.astype(np.float64) + matrices[k, :2, 3]
        pixel = np.floor((clip + 1.0) * 0.5 * sizes[k])
        inside = ((pixel >= windows[k, :2]) & (pixel < windows[k, :2] + windows[k, 2:])).all(axis=1)
        assert inside.any() and meets[k][inside].all()
        assert not meets[k][(np.abs(pixel - (windows[k, :2] + windows[k, 2:] / 2)) > sizes[k] / 3).any(axis=1)].any()
