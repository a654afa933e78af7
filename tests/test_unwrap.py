# SPDX-License-Identifier: GPL-3.0-or-later
"""The xatlas unwrap at any scale and offset, its errors, and stopping it at once."""
from __future__ import annotations

import os
import tempfile
import time
from pathlib import Path

import numpy as np
import pytest

from conftest import DATA
from hao_addon.core.geometry import uv_areas
from hao_addon.core.objfile import read_obj
from hao_addon.core.bake.unwrap import UnwrapError, run_unwrap, unwrap_steps, xatlas_unwrap

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
    np.testing.assert_array_equal(xatlas_unwrap(v, t, 512), run_unwrap(v, t, 512))


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
