# SPDX-License-Identifier: GPL-3.0-or-later
"""numpy's BLAS pool is held to one thread while a bake runs (core/blas_threads.py: its
spinning workers took the cores llvmpipe needs) and gets its own count back afterwards, also
when the bake fails or is stopped part-way."""
from __future__ import annotations

import numpy as np
import pytest

from hao_addon.bake import bake, bake_steps
from hao_addon.core import scenes
from hao_addon.core.blas_threads import blas_pool, single_threaded_blas
from hao_addon.core.bake.settings import BakeSettings
from hao_addon.core.errors import BakeInputError


@pytest.fixture
def pool():
    """The pool, at two threads for the test (a one-core machine reports one)."""
    found = blas_pool()
    assert found is not None, "numpy's wheels ship OpenBLAS: its pool should be found"
    before = found.threads()
    found.set_threads(2)
    yield found
    found.set_threads(before)


def test_the_block_holds_one_thread_and_restores_the_count(pool):
    with single_threaded_blas() as before:
        assert before == 2 and pool.threads() == 1
        np.ones((64, 64)) @ np.ones((64, 64))  # BLAS still works, on one thread
    assert pool.threads() == 2


def test_a_bake_holds_one_thread_throughout_and_restores_it(gpu_context, pool):
    seen = []
    settings = BakeSettings(size=32, directions=8, method="gather", margin=0)
    result = bake(scenes.grid_plane(2.0, 4), [], settings, progress=lambda _: seen.append(pool.threads()),
                  use_cache=False)
    assert result.stats["blas_threads_held"] is True
    assert seen and set(seen) == {1}
    assert pool.threads() == 2


def test_a_failed_or_stopped_bake_restores_the_count(gpu_context, pool):
    plane = scenes.grid_plane(2.0, 4)
    plane.uvs = None  # no UVs: refused
    with pytest.raises(BakeInputError):
        bake(plane, [], BakeSettings(size=32, directions=8, method="gather"), use_cache=False)
    assert pool.threads() == 2
    steps = bake_steps(scenes.grid_plane(2.0, 4), [], BakeSettings(size=32, directions=8, method="gather"),
                       use_cache=False)
    next(steps)
    assert pool.threads() == 1
    steps.close()  # the operator's cancel
    assert pool.threads() == 2
