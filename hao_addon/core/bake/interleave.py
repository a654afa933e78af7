# SPDX-License-Identifier: GPL-3.0-or-later
"""Texel classes (the setting Texel Sets): neighbouring texels bake with differently rotated
direction sets.

Every texel sees D directions, and if every texel sees the same D, a direction's hard
shadow edge lies at the same place for all of them: the map's error is rings and polygons
(one per direction) that an artist sees at once and no filter of the map removes. Under a
ball resting on an 8-unit floor at 1024^2 with 256 directions, 0.0054 of the 0.0071 RMSE in
its shadow survived an 8 x 8 box filter (white noise of that RMSE would filter to 0.0009).

With Texel Sets 2 x 2 the texels are split into CLASSES in a SIDE x SIDE pattern, each class
with its own directions (core/directions.class_directions: every CLASSES-th point of one
lattice): each texel's error is what it was, but its neighbours' are the errors of other
sets, and what the eye averages over a few texels is the whole lattice (the same scene:
0.0017 after the filter; bench/structured_error_bench.py). The gather draws CLASSES views per
direction and tests each class's entries against its own views alone, so its texel tests are
as many as with one set.

Why not the default yet: on llvmpipe the views' fixed costs (draws, clears, a dispatch each)
fourfold made Spot's whole bake at the defaults 1.28x as long, and the coarser views
(class_pixel_scale) hide more near other surfaces (a floor at a wall: bent normals 2.4 degrees
off where one set errs 0.8).
"""
from __future__ import annotations

import numpy as np

SIDE = 2
CLASSES = SIDE * SIDE


def texel_classes(texels: np.ndarray, size: int, side: int = SIDE) -> np.ndarray:
    """(n,) int the class of each flat texel index (texels (n,) into a (tiles, size, size) or
    (size, size) output): its column and row modulo side."""
    texels = np.asarray(texels, np.int64)
    return (texels % size) % side + side * ((texels // size) % size % side)


def classes_for(interleaves: bool, per_element: bool, directions: int, texel_sets: int) -> int:
    """The texel classes of a bake: texel_sets (the setting: 1 or CLASSES) where its baker can
    give texels different directions (abilities.interleaves) and its output is texels (not
    colour-attribute elements, which have no neighbours in a map) seen from two directions or
    more, else 1."""
    return texel_sets if interleaves and not per_element and directions >= 2 else 1


def class_pixel_scale(classes: int) -> float:
    """How many times wider a light-view pixel is with `classes` texel classes: a class's
    texels lie SIDE apart, and its views sample them at View Samples pixels per texel as a
    bake without classes samples all of them. Views as fine as without classes cost the
    gather's texel tests 1.8x their time on llvmpipe (each class reads one pixel in four of
    its views: the floor under a ball, 1024^2, 256 directions: 5.3 s against 2.9 s), and four
    times the pixels to clear; the coarser views raise Spot's RMSE against an exact truth at
    256^2, 1024 directions, flat, from 0.00356 to 0.00376 (one class: 0.00350), where their
    depth slack hides more (the stated floor 0.0010 -> 0.0015 RMSE)."""
    return float(SIDE) if classes > 1 else 1.0
