# SPDX-License-Identifier: GPL-3.0-or-later
"""numpy's BLAS thread pool, held to one thread while a bake runs (no bpy, no gpu).

numpy's wheels (and so Blender's Python and the bpy wheels) link OpenBLAS, whose worker
threads spin for a while after each call large enough to wake them. A bake's numpy work is
small matrices (views, cones, a few million vertices times 3x3) that one thread does as fast,
while the GPU driver needs the cores: with llvmpipe (Mesa's CPU OpenGL), on a 2-core machine,
the spinning workers took 9.5 % of the CPU samples of a 96-direction gather of the smooth bunny
(perf), and the bake ran 12 % faster with one BLAS thread (2.20 s against 2.51 s, medians of
8 runs interleaved in one process). Where no OpenBLAS is found (Accelerate on Apple silicon, a numpy built
without it), nothing changes.
"""
from __future__ import annotations

import contextlib
import ctypes
import glob
import os
import sys
from typing import Iterator

import numpy as np

# (get, set) symbol names of the OpenBLAS builds numpy ships: numpy 2 (scipy-openblas, 64-bit
# integers), numpy 1.x's 64-bit-integer build, a plain build.
_SYMBOLS = (("scipy_openblas_get_num_threads64_", "scipy_openblas_set_num_threads64_"),
            ("openblas_get_num_threads64_", "openblas_set_num_threads64_"),
            ("openblas_get_num_threads", "openblas_set_num_threads"))


class BlasPool:
    """One loaded OpenBLAS library's thread count."""

    def __init__(self, library: ctypes.CDLL, get_name: str, set_name: str) -> None:
        self._get = getattr(library, get_name)
        self._get.restype = ctypes.c_int
        self._set = getattr(library, set_name)
        self._set.argtypes = [ctypes.c_int]
        self._set.restype = None

    def threads(self) -> int:
        return int(self._get())

    def set_threads(self, count: int) -> None:
        self._set(int(count))


def _candidate_paths() -> list[str]:
    """Files that may hold numpy's OpenBLAS: the wheel's bundled libraries, else (Linux) the
    shared objects this process has mapped whose name says openblas."""
    root = os.path.dirname(np.__file__)
    paths = []
    for folder in (os.path.join(os.path.dirname(root), "numpy.libs"), os.path.join(root, ".libs"),
                   os.path.join(root, ".dylibs")):
        paths += sorted(glob.glob(os.path.join(folder, "*openblas*")))
    if not paths and sys.platform.startswith("linux"):
        try:
            with open("/proc/self/maps", encoding="utf-8", errors="replace") as maps:
                mapped = {line.split()[-1] for line in maps if "openblas" in line and "/" in line}
            paths = sorted(mapped)
        except OSError:
            pass
    return paths


_POOL: list[BlasPool | None] = []  # found once per session: [] = not looked for yet


def blas_pool() -> BlasPool | None:
    """numpy's OpenBLAS thread pool, or None where there is none to control."""
    if not _POOL:
        _POOL.append(_find_pool())
    return _POOL[0]


def _find_pool() -> BlasPool | None:
    for path in _candidate_paths():
        try:
            library = ctypes.CDLL(path)  # already loaded by numpy: the same library
        except OSError:
            continue
        for get_name, set_name in _SYMBOLS:
            if hasattr(library, get_name) and hasattr(library, set_name):
                return BlasPool(library, get_name, set_name)
    return None


@contextlib.contextmanager
def single_threaded_blas() -> Iterator[int | None]:
    """Hold numpy's BLAS to one thread inside the block and restore its count after; yields
    the count it had (None where there is no pool to control)."""
    pool = blas_pool()
    if pool is None:
        yield None
        return
    before = pool.threads()
    pool.set_threads(1)
    try:
        yield before
    finally:
        pool.set_threads(before)
