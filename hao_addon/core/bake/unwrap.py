# SPDX-License-Identifier: GPL-3.0-or-later
"""Automatic UV atlas for meshes that have no UV map (CPU; no bpy): planar charts
(``charts.py``) packed by xatlas (``unwrap_worker.py``).

Two things make it safe to run on any mesh here:
- scale: xatlas' epsilons are absolute, so a mesh of 1e10 units ran for minutes and one of
  1e-4 units packed nothing. It unwraps a copy centred and scaled to unit size; UVs do not
  depend on scale, so the real positions are never needed.
- interrupts: xatlas holds the interpreter lock until it returns, so the unwrap runs in a
  child process that is killed at once on Ctrl-C, SIGTERM or Esc.
"""
from __future__ import annotations

import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Generator

import numpy as np

from ..errors import BakeInputError
from ..steps import drain
from .charts import overlapping_texels
from .unwrap_worker import UNWRAPS

# xatlas' padding around each chart, in texels of the texture, on top of its one-texel
# bilinear border and conservative rasterization: with 1, at least three texels lie clear
# between two charts' covered texels (measured on the bunny at 256^2 and 1024^2; the tests
# require two, so the bake's one-texel tent and bilinear lookups never mix charts).
DEFAULT_PADDING = 1
# A triangle whose area is below this fraction of the (unit) bounding box is treated as
# degenerate when deciding whether anything can be unwrapped at all.
MIN_RELATIVE_AREA = 1e-14
POLL_SECONDS = 0.02
WORKER = Path(__file__).with_name("unwrap_worker.py")


class UnwrapError(BakeInputError):
    """The mesh cannot be unwrapped; the message says why."""


def check_unwrap_overlap(written: np.ndarray, size: int, name: str = "mesh") -> int:
    """Raise UnwrapError when the UVs as written (F, 3, 2: what a bake reads back) put a
    texel centre of the size x size map inside two triangles: such a map would be wrong,
    so it is a failure, never a warning. Returns the texels covered."""
    overlap, covered = overlapping_texels(written, size)
    if overlap:
        raise UnwrapError(f"the automatic UVs of '{name}' overlap on {overlap} of {covered} texels "
                          f"({100.0 * overlap / max(covered, 1):.2g} %): nothing was baked; give it a UV map")
    if not covered:
        raise UnwrapError(f"the automatic UVs of '{name}' cover no texel of a {size}^2 map")
    return covered


def unit_copy(vertices: np.ndarray, triangles: np.ndarray, name: str = "mesh") -> np.ndarray:
    """(V, 3) float32: the vertices centred on their box and scaled so its longest side is 1.

    Raises UnwrapError for meshes that cannot be unwrapped: no triangles, non-finite or
    out-of-range indices, or no triangle with area."""
    v = np.asarray(vertices, np.float64)
    t = np.asarray(triangles)
    if len(t) == 0 or len(v) == 0:
        raise UnwrapError(f"'{name}' has no triangles to unwrap")
    if t.min() < 0 or t.max() >= len(v):
        raise UnwrapError(f"'{name}' has triangle indices outside its {len(v)} vertices")
    used = v[np.unique(t)]
    if not np.isfinite(used).all():
        raise UnwrapError(f"'{name}' has NaN or infinite vertex positions: cannot unwrap it")
    lo, hi = used.min(axis=0), used.max(axis=0)
    extent = float((hi - lo).max())
    if not extent > 0.0:
        raise UnwrapError(f"'{name}' has only zero-area triangles: nothing to unwrap")
    unit = (v - (lo + hi) * 0.5) / extent
    p = unit[t]
    area2 = np.linalg.norm(np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]), axis=1)
    if not (area2 > 2.0 * MIN_RELATIVE_AREA).any():
        raise UnwrapError(f"'{name}' has only zero-area triangles: nothing to unwrap")
    return unit.astype(np.float32)


def unwrap_in_process(vertices: np.ndarray, triangles: np.ndarray, resolution: int,
                      padding: int = DEFAULT_PADDING, name: str = "mesh",
                      polygons: np.ndarray | None = None, way: str = "charts") -> np.ndarray:
    """Per-corner UVs (F, 3, 2) float64 in [0, 1], in this process (blocks until done).

    vertices: (V, 3) float, any scale and offset; triangles: (F, 3) int vertex indices;
    resolution: the texture size the atlas is packed for; polygons: (F,) each triangle's
    polygon (a polygon's triangles land in one chart) or None; way: 'charts' (planar charts
    packed by xatlas) or 'xatlas' (xatlas' own charts: the fallback, unwrap_worker.UNWRAPS)."""
    unit = unit_copy(vertices, triangles, name)
    try:
        return UNWRAPS[way](unit, np.asarray(triangles, np.uint32), resolution, padding, polygons)
    except RuntimeError as exc:
        raise UnwrapError(f"cannot unwrap '{name}': {exc}") from None


def worker_python() -> str | None:
    """The interpreter for the child, or None where this process has none to start (an
    embedding without a Python executable): then the unwrap runs in-process."""
    exe = sys.executable
    if exe and Path(exe).is_file() and Path(exe).name.lower().startswith("python"):
        return exe
    return None


def unwrap_steps(vertices: np.ndarray, triangles: np.ndarray, resolution: int,
                 padding: int = DEFAULT_PADDING, name: str = "mesh",
                 polygons: np.ndarray | None = None, way: str = "charts") -> Generator[None, None, np.ndarray]:
    """Like unwrap_in_process, in a child process: yields while it runs (poll, report progress,
    or close the generator to kill it), returns the UVs (F, 3, 2).

    Closing the generator, or an exception in the caller while it is suspended (Ctrl-C),
    kills the child and removes its temporary folder at once."""
    unit = unit_copy(vertices, triangles, name)
    python = worker_python()
    if python is None:
        yield
        return unwrap_in_process(unit, triangles, resolution, padding, name, polygons, way)
    folder = tempfile.mkdtemp(prefix="hao-unwrap-")
    proc = None
    try:
        source, target = os.path.join(folder, "in.npz"), os.path.join(folder, "out.npy")
        extra = {} if polygons is None else {"polygons": np.asarray(polygons, np.int64)}
        np.savez(source, vertices=unit, triangles=np.asarray(triangles, np.uint32),
                 resolution=np.int64(resolution), padding=np.int64(padding), way=np.str_(way), **extra)
        env = {**os.environ, "PYTHONPATH": os.pathsep.join(p for p in sys.path if p)}
        with open(os.path.join(folder, "err.txt"), "wb") as err:
            proc = subprocess.Popen([python, str(WORKER), source, target], stdin=subprocess.DEVNULL,
                                    stdout=subprocess.DEVNULL, stderr=err, env=env)
        while proc.poll() is None:
            yield
            time.sleep(POLL_SECONDS)
        if proc.returncode != 0:
            message = Path(folder, "err.txt").read_text(errors="replace").strip().splitlines()
            raise UnwrapError(f"cannot unwrap '{name}': {message[-1] if message else f'exit {proc.returncode}'}")
        return np.load(target)
    finally:
        if proc is not None and proc.poll() is None:
            proc.kill()
            proc.wait()
        shutil.rmtree(folder, ignore_errors=True)


def run_unwrap(vertices: np.ndarray, triangles: np.ndarray, resolution: int,
               padding: int = DEFAULT_PADDING, name: str = "mesh", polygons: np.ndarray | None = None,
               way: str = "charts") -> np.ndarray:
    """Blocking unwrap in a child process (interruptible); returns (F, 3, 2) UVs."""
    return drain(unwrap_steps(vertices, triangles, resolution, padding, name, polygons, way))
