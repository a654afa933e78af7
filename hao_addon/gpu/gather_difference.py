# SPDX-License-Identifier: GPL-3.0-or-later
"""The scene before an edit, in a gather of a re-bake by difference (plan.before_drawn,
hao_addon/rebake_difference.py): its faces in compact chunks, drawn in each view's window
into a depth map of their own just before that direction's map of the edited scene, and read
by the same dispatch as a view that subtracts (gpu_shaders/bake_gather.comp, DIFFERENCE)."""
from __future__ import annotations

import numpy as np

from ..core.bake.entry_blocks import intersected_runs
from ..core.bake.face_chunks import face_chunks, hole_chunk_ranges_many, window_chunk_ranges_many
from .light_view import depth_prepass, positions_batch


def window_arrays(views: list) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """((k, 4, 4) whole views' matrices, (k, 2) their sizes, (k, 4) the windows x, y, width,
    height) of k cropped views (OrthoView.whole)."""
    return (np.stack([v.whole.matrix for v in views]), np.array([(v.whole.width, v.whole.height) for v in views]),
            np.array([(*v.first, v.width, v.height) for v in views]))


def runs_within(averted: list[tuple[int, int]], window: list[tuple[int, int]]) -> list[tuple[int, int]]:
    """The (first face, face count) runs of averted that lie in the (first, end) runs of a
    window's faces (both in the chunks' draw order)."""
    inside = intersected_runs([(first, first + count) for first, count in averted], window)
    return [(first, end - first) for first, end in inside]


class SceneBefore:
    """The before-scene part of GatherBaker (its plan, depth_fbs, pending and stats are the
    baker's)."""

    def _before_setup(self) -> None:
        """plan.before_drawn: (its drawn triangles (F', 3, 3), its holes as plan.holes)."""
        self.before_chunks = self.before_batch = self.before_holes = None
        self.before_runs: dict[int, tuple[list, list]] = {}
        if self.plan.before_drawn is not None:
            drawn, self.before_holes = self.plan.before_drawn
            self.before_chunks = face_chunks(drawn)
            self.before_batch = positions_batch(drawn[self.before_chunks.order])

    def _before_fitted(self, indices: list[int], views: list) -> None:
        """The before scene's runs in the windows of a batch of (cropped) views: (its window's
        faces as (first, end), its averted faces near holes there as (first, count))."""
        self.before_runs = {}
        if self.before_chunks is None:
            return
        count = len(self.before_chunks.order)
        arrays = window_arrays(views)
        windows = window_chunk_ranges_many(self.before_chunks, *arrays, count)
        holes = [[] for _ in views]
        if self.before_holes is not None and not self.plan.settings.ignore_back_faces:
            holes = hole_chunk_ranges_many(self.before_chunks, self.before_holes, arrays[0], count)
        for index, window, averted in zip(indices, windows, holes):
            window = [(first, first + n) for first, n in window]
            self.before_runs[index] = (window, runs_within(averted, window))

    def _draw_before(self, index: int, view) -> None:
        """Direction `index`'s depth map of the scene before, pending with sign -1: culled as
        its own whole bake culls (GatherBaker._depth_map_faces), its window's faces alone."""
        window, averted = self.before_runs[index]
        if self.plan.settings.ignore_back_faces:
            culling = 'FRONT'
        else:
            culling = 'NONE' if self.before_holes is None else 'BACK'
        depth_prepass(self.depth_fbs[len(self.pending)], self.before_batch, view, culling, averted,
                      (self.before_batch, window), positions_only=True)
        self.pending.append(view)
        self.pending_signs.append(-1.0)
        self.stats["view_pixels"] += view.width * view.height

    def _before_release(self) -> None:
        self.before_chunks = self.before_batch = self.before_holes = None
        self.before_runs = {}
