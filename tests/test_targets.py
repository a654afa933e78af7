# SPDX-License-Identifier: GPL-3.0-or-later
"""The bake target type (core/bake/targets.py, issue 30 item 0): three kinds as rows of data,
one type the plan, the bake and the job take."""
from __future__ import annotations

import numpy as np
import pytest

from hao_addon.core import scenes
from hao_addon.core.bake.plan import make_plan
from hao_addon.core.bake.projection import HighToLow
from hao_addon.core.bake.settings import BakeSettings
from hao_addon.core.bake.target_kinds import TARGET_KINDS
from hao_addon.core.bake.targets import BakeTarget
from hao_addon.core.bake.vertex_target import indexed_vertex_target
from hao_addon.core.errors import BakeInputError
from hao_addon.core.geometry import TriangleSoup

SETTINGS = BakeSettings(size=32, directions=4)


def corners_of(soup: TriangleSoup):
    verts, index = np.unique(soup.positions.reshape(-1, 3).round(9), axis=0, return_inverse=True)
    return indexed_vertex_target(index.reshape(-1, 3), len(verts))


def test_the_settings_and_inputs_resolve_to_one_kind():
    plane = scenes.grid_plane(2.0, 2)
    corners = corners_of(plane)
    assert BakeTarget.of(plane, "image").kind is TARGET_KINDS["texels"]
    assert BakeTarget.of(plane, "image", HighToLow([plane])).kind is TARGET_KINDS["projected"]
    colour = BakeTarget.of(plane, "color-attribute", vertex_target=corners)
    assert colour.kind is TARGET_KINDS["corners"] and colour.corners is corners
    assert BakeTarget.of(plane, "image", vertex_target=corners).corners is None  # an image bake has no corners


def test_each_kind_refuses_what_it_cannot_bake():
    plane = scenes.grid_plane(2.0, 2, name="plane")
    no_uv = TriangleSoup(plane.positions, None, "bare")
    with pytest.raises(BakeInputError, match="'bare' has no UV map"):
        BakeTarget.of(no_uv, "image").check(False)
    BakeTarget.of(no_uv, "color-attribute", vertex_target=corners_of(plane)).check(False)  # needs no UVs
    with pytest.raises(BakeInputError, match="needs the mesh's vertices and corners"):
        BakeTarget.of(plane, "color-attribute").check(False)
    with pytest.raises(BakeInputError, match="bent normals bake into images"):
        BakeTarget.of(plane, "color-attribute", vertex_target=corners_of(plane)).check(True)
    with pytest.raises(BakeInputError, match="no faces to bake"):
        BakeTarget.of(TriangleSoup(np.zeros((0, 3, 3)), None, "empty"), "image").check(False)


def test_a_plan_of_a_target_equals_the_plan_of_its_parts():
    """make_plan takes a BakeTarget or the mesh with its parts as keywords: the same plan."""
    import bpy  # noqa: F401 - mathutils for the CPU ray cast
    relief = [scenes.grid_plane(4.0, 8, name="floor"), scenes.uv_sphere(0.5, (0, 0, 0.5), 16, 8, name="ball")]
    low = scenes.grid_plane(2.0, 2, z=1.2, name="low")
    request = HighToLow(relief)
    by_parts = make_plan(low, [], SETTINGS, high_to_low=request)
    by_target = make_plan(BakeTarget.of(low, "image", request), [], SETTINGS)
    assert by_target.kind is by_parts.kind is TARGET_KINDS["projected"]
    assert not by_target.target_drawn  # the row: Selected to Active's low-poly does not occlude
    np.testing.assert_array_equal(by_target.layout.projected.points, by_parts.layout.projected.points)
    np.testing.assert_array_equal(by_target.drawn_positions, by_parts.drawn_positions)
    own = make_plan(BakeTarget.of(low, "image"), relief, SETTINGS)
    assert own.target_drawn and len(own.drawn_positions) == low.face_count + sum(s.face_count for s in relief)
