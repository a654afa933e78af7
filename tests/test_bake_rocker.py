# SPDX-License-Identifier: GPL-3.0-or-later
"""The rocker arm of McGraw & Sowers' Table 1 against the ray-traced reference."""
from __future__ import annotations

import numpy as np
import pytest

from bake_helpers import sigma
from conftest import DATA
from hao_addon.bake import bake
from hao_addon.core.geometry import face_normals_areas
from hao_addon.core.objfile import obj_soup
from hao_addon.core.reference import reference_accessibility
from hao_addon.core.bake.settings import BakeSettings
from hao_addon.core.bake.uv_raster import interior_mask, texel_surface_samples
from hao_addon.core.bake.abilities import bakers_with

SIZE, DIRS, REF_RAYS, TEXELS = 512, 128, 256, 400


@pytest.fixture(scope="module")
def rocker():
    soup = obj_soup(DATA / "rocker-arm.obj", uvs="auto", size=SIZE)
    assert soup.face_count == 20088
    face, bary, hits = texel_surface_samples(soup.uvs, SIZE)
    inner = interior_mask(face, hits)
    rng = np.random.default_rng(7)
    ys, xs = np.nonzero(inner)
    pick = rng.choice(len(ys), TEXELS, replace=False)
    ys, xs = ys[pick], xs[pick]
    f = face[ys, xs]
    pts = np.einsum("nk,nkd->nd", bary[ys, xs], soup.positions[f])
    normals, _ = face_normals_areas(soup.positions)
    ref = reference_accessibility(pts, normals[f], soup.positions, rays=REF_RAYS, seed=3)
    return soup, ys, xs, ref


@pytest.mark.parametrize("method", bakers_with(gpu_only=True))
def test_rocker_arm_matches_ray_traced_reference(gpu_context, rocker, method):
    soup, ys, xs, ref = rocker
    res = bake(soup, [], BakeSettings(size=SIZE, directions=DIRS, method=method), use_cache=False)
    e = res.ao[ys, xs] - ref
    rmse, bias = float(np.sqrt((e**2).mean())), float(e.mean())
    # Both sides are estimates: combine the bake's and the reference's sample-count bounds.
    s = np.hypot(sigma(DIRS), 0.5 / np.sqrt(REF_RAYS))
    assert rmse <= s / 2, (method, rmse, s / 2)
    assert abs(bias) <= s / 8, (method, bias, s / 8)
    assert 0.2 < ref.mean() < 0.95 and ref.std() > 0.05  # the sample is not trivially open
