# SPDX-License-Identifier: GPL-3.0-or-later
"""Connected parts of a graph given as edge pairs: the labelling that the unwrap's charts
(core/bake/charts.py) and the closed-surface test (core/geometry.surface_holes) share.
Imports only numpy: the unwrap's child process loads it by file name."""
from __future__ import annotations

import numpy as np


def connected_components(count: int, pairs: np.ndarray) -> np.ndarray:
    """(count,) component index 0..C-1 of each node of an undirected graph with edges
    pairs (P, 2)."""
    return np.unique(root_labels(count, pairs), return_inverse=True)[1].reshape(-1)


def root_labels(count: int, pairs: np.ndarray) -> np.ndarray:
    """(count,) the smallest node of each node's component, for edges pairs (P, 2): hooking
    of roots plus pointer jumping, a few array passes even on long chains (6 for the
    35k-vertex bunny's triangles)."""
    label = np.arange(count)
    while True:
        low = np.minimum(label[pairs[:, 0]], label[pairs[:, 1]])
        before = label.copy()
        # Hook each root to the lowest root it touches, then jump every node to its root.
        np.minimum.at(label, label[pairs[:, 0]], low)
        np.minimum.at(label, label[pairs[:, 1]], low)
        while True:
            jumped = label[label]
            if np.array_equal(jumped, label):
                break
            label = jumped
        if np.array_equal(label, before):
            return label
