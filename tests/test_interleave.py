# SPDX-License-Identifier: GPL-3.0-or-later
"""Texel classes (core/bake/interleave.py): neighbouring texels bake with differently rotated
direction sets, so that the default bake's error is grain, not the polygons of one set's
shadows (issue 56 item 2)."""
from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from hao_addon.bake import bake
from hao_addon.core import scenes
from hao_addon.core.bake import interleave
from hao_addon.core.bake.abilities import BAKERS
from hao_addon.core.bake.interleave import CLASSES, SIDE, texel_classes
from hao_addon.core.bake.settings import BakeSettings
from hao_addon.core.directions import (CLASS_LATTICE_STEP, GOLDEN_ANGLE, class_directions, fibonacci_sphere,
                                       random_rotation, replicate_sizes)

RADIUS = 0.5
BOX = 8  # the filter: what the eye averages, structure survives and noise does not


def test_texel_classes_tile_the_map_in_a_square_pattern():
    size = 6
    flat = np.arange(2 * size * size)  # two UDIM tiles
    classes = texel_classes(flat, size).reshape(2, size, size)
    assert (classes[:, :SIDE, :SIDE].reshape(2, -1) == np.arange(CLASSES)).all()
    assert (classes[:, SIDE:, SIDE:] == classes[:, :-SIDE, :-SIDE]).all() and (classes[0] == classes[1]).all()


@pytest.mark.parametrize("count", [2, 7, 64, 256])
def test_each_class_sees_a_whole_fibonacci_set_and_together_a_lattice(count):
    """Every class gets `count` directions split between the replicates as a bake without
    classes splits them; each of its replicate's sets is a spherical Fibonacci set (the golden
    azimuth step, its z evenly spaced), under the replicate's own rotation, and the classes'
    points together are one lattice of four times as many points."""
    directions, served = class_directions(count, 11, CLASSES)
    assert np.bincount(served, minlength=CLASSES).tolist() == [count] * CLASSES
    starts = np.cumsum([0, *replicate_sizes(CLASSES * count)])
    for r, (a, b) in enumerate(zip(starts[:-1], starts[1:])):
        local = directions[a:b] @ random_rotation(11, r)  # undo the replicate's rotation
        n = b - a
        np.testing.assert_allclose(local[:, 2], 1.0 - (2.0 * np.arange(n) + 1.0) / n, atol=1e-12)
        for k in range(CLASSES):
            own = local[served[a:b] == k]
            step = np.mod(np.diff(np.arctan2(own[:, 1], own[:, 0])) / (2 * np.pi), 1.0)
            golden = 1.0 - GOLDEN_ANGLE / (2 * np.pi)
            assert len(own) in (n // CLASSES, -(-n // CLASSES))
            assert np.allclose(step, golden, atol=1e-9) or np.allclose(step, 1.0 - golden, atol=1e-9)
    assert CLASS_LATTICE_STEP[CLASSES] * CLASSES % 1.0 == pytest.approx(1.0 - GOLDEN_ANGLE / (2 * np.pi))


def test_one_class_is_the_set_without_classes():
    from hao_addon.core.directions import bake_directions
    directions, served = class_directions(100, 5, 1)
    np.testing.assert_array_equal(directions, bake_directions(100, 5))
    assert not served.any()
    assert np.allclose(fibonacci_sphere(8) @ random_rotation(5, 0).T, bake_directions(16, 5)[:8])


def test_the_bakers_that_interleave_are_declared():
    assert {b.method for b in BAKERS if b.interleaves} == {"gather", "reference"}
    assert interleave.classes_for(True, False, 256, CLASSES) == CLASSES
    assert interleave.classes_for(True, True, 256, CLASSES) == 1  # colour attributes: no neighbours in a map
    assert interleave.classes_for(False, False, 256, CLASSES) == 1 and interleave.classes_for(True, False, 1, CLASSES) == 1
    assert interleave.classes_for(True, False, 256, 1) == 1


def _floor_and_ball():
    return scenes.grid_plane(8.0, 1, name="floor"), scenes.uv_sphere(RADIUS, (0.0, 0.0, RADIUS), 64, 32, name="ball")


def _floor_under_ball_error(size: int, directions: int, texel_sets: int) -> tuple[float, float]:
    """(RMSE, RMSE after a BOX x BOX box filter) of the default bake of an 8-unit floor under a
    ball resting on it, against 1 - (R / D)^3 (core/scenes.py), where the ball's shadow
    reaches (the exact AO below 0.99)."""
    floor, ball = _floor_and_ball()
    result = bake(floor, [ball], BakeSettings(size=size, directions=directions, texel_sets=texel_sets),
                  use_cache=False)
    u = ((np.arange(size) + 0.5) / size - 0.5) * 8.0
    x, y = np.meshgrid(u, u)
    exact = 1.0 - (RADIUS / np.sqrt(x * x + y * y + RADIUS * RADIUS)) ** 3
    error = result.ao - exact
    blocks = size // BOX
    boxed = error.reshape(blocks, BOX, blocks, BOX).mean(axis=(1, 3))
    shadow, boxed_shadow = exact < 0.99, exact.reshape(blocks, BOX, blocks, BOX).mean(axis=(1, 3)) < 0.99
    return float(np.sqrt((error[shadow] ** 2).mean())), float(np.sqrt((boxed[boxed_shadow] ** 2).mean()))


def test_texel_sets_turn_shadow_shapes_into_grain(gpu_context):
    """Issue 56 item 2: at 1024^2, 256 directions (the gather), under a ball resting on a floor,
    Texel Sets 2 x 2 leave at most 0.003 RMS of error after an 8 x 8 box filter (one set for
    every texel: 0.0054), and each texel's own error is no larger than with one set (its 256
    directions are a Fibonacci set as before: 0.0070 and 0.0071 RMSE in the shadow)."""
    rmse, boxed = _floor_under_ball_error(1024, 256, CLASSES)
    rmse_one, boxed_one = _floor_under_ball_error(1024, 256, 1)
    assert boxed <= 0.003, f"structured error {boxed:.4f} (one set: {boxed_one:.4f})"
    assert boxed_one > 0.0045  # the scene shows what the classes remove
    assert rmse <= 1.05 * rmse_one, f"each texel's error {rmse:.4f}, one set {rmse_one:.4f}"


def test_the_reference_twin_bakes_each_texel_from_its_own_set(gpu_context):
    """The gather and its CPU twin give each texel class the same directions: with Texel Sets
    2 x 2 they differ by the gather's visibility floor (at 128^2, 16 directions: 0.034 RMS in
    the shadow, as with one set), far less than a bake of one set differs from them (the
    directions' noise: 0.12)."""
    floor, ball = _floor_and_ball()
    settings = BakeSettings(size=128, directions=16, margin=0, texel_sets=CLASSES)
    gather = bake(floor, [ball], settings, use_cache=False)
    reference = bake(floor, [ball], replace(settings, method="reference"), use_cache=False)
    one = bake(floor, [ball], replace(settings, texel_sets=1), use_cache=False)
    assert gather.stats["directions_done"] == CLASSES * 16 and one.stats["directions_done"] == 16
    assert gather.stats["texel_sets"] == reference.stats["texel_sets"] == CLASSES and one.stats["texel_sets"] == 1
    scatter = bake(floor, [ball], replace(settings, method="scatter", size=32), use_cache=False)
    assert scatter.stats["texel_sets"] == 1 and scatter.stats["directions_done"] == 16  # it bakes one set
    shadow = gather.ao < 0.99

    def rms(a, b):
        return float(np.sqrt(((a.ao - b.ao)[shadow] ** 2).mean()))
    assert rms(gather, reference) < 0.5 * rms(gather, one), (rms(gather, reference), rms(gather, one))
