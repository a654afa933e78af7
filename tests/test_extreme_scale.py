# SPDX-License-Identifier: GPL-3.0-or-later
"""Meshes at extreme scales: Blender's float32 normals of a tiny mesh are garbage (a UV
sphere of radius 1e-9: corners up to 169 degrees from their faces), and a lone convex sphere
baked down to 0.02 where it must read 1. Shading normals that are zero or not finite are
baked flat, with a warning."""
from __future__ import annotations

import numpy as np
import pytest

import bpy
from conftest import select_only, small_settings
from hao_addon.bake import bake
from hao_addon.core import scenes
from hao_addon.core.bake.settings import BakeSettings


@pytest.mark.parametrize("radius", [1e-9, 1.0, 3e19])
def test_a_lone_smooth_sphere_is_open_at_every_scale(scene, radius):
    from hao_addon.blender.bake_job import BakeJob
    bpy.ops.mesh.primitive_uv_sphere_add(radius=radius, segments=32, ring_count=16)
    sphere = bpy.context.object
    bpy.ops.object.shade_smooth()
    select_only(sphere)
    settings = small_settings(scene, directions=32, size=64, margin=0, method='gather')
    job = BakeJob(settings.to_request([sphere]), bpy.context.evaluated_depsgraph_get)
    job.run()
    result = job.results[0][2]
    assert result.stats["smooth_corners"] > 0  # smooth shading was read, and right
    np.testing.assert_allclose(result.ao[result.covered], 1.0, atol=1e-4)
    assert not [w for w in result.stats["warnings"] if "normal" in w]


def test_zero_and_nan_shading_normals_bake_flat_and_say_so(gpu_context):
    sphere = scenes.uv_sphere(1.0, (0.0, 0.0, 0.0), 16, 8)
    p = sphere.positions
    normals = p / np.linalg.norm(p, axis=2, keepdims=True)
    normals[:10] = 0.0
    normals[10:12, 0] = np.nan
    sphere.normals = normals
    res = bake(sphere, [], BakeSettings(size=64, directions=32, method="gather", margin=0), use_cache=False)
    np.testing.assert_allclose(res.ao[res.covered], 1.0, atol=1e-4)
    assert any("32 of its" in w and "zero or not finite" in w for w in res.stats["warnings"]), res.stats["warnings"]
