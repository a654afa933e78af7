# SPDX-License-Identifier: GPL-3.0-or-later
"""Frame lists in Open Job Description's range syntax: '1-48', '1-48:2', '5', and several of
them joined by commas ('1-3,5,7-20:2'); negative frames too ('-10--1'). The command line's
--frames and a farm task's chunk of frames are written this way.

Counts are taken from the ranges before any list is made, so a typo such as 1-1000000000
is refused at once instead of filling memory.
"""
from __future__ import annotations

import re

from .errors import BakeInputError

# At most this many frames in one --frames (a typo such as 1-100000 is refused).
MAX_FRAMES = 10_000
# Blender's frame range (MINAFRAME, MAXFRAME): a scene cannot be set to a frame outside it
# (it would be clamped silently, and every such frame bake the same scene).
BLENDER_FRAMES = (-1_048_574, 1_048_574)
_ITEM = re.compile(r"\s*(-?\d+)\s*(?:-\s*(-?\d+))?\s*(?::\s*(\d+))?\s*")


def frame_ranges(spec: str) -> list[range]:
    """The ranges of 'A', 'A-B' or 'A-B:STEP' items joined by commas (A <= B, STEP >= 1),
    checked and counted (at most MAX_FRAMES frames, none twice) without listing them."""
    ranges = []
    for item in spec.split(","):
        match = _ITEM.fullmatch(item)
        if match is None:
            raise BakeInputError(f"--frames '{spec}': expected A-B or A-B:STEP, several joined by commas (for "
                                 f"example 1-48, 1-48:2 or 1-3,5,7-20:2)")
        first = int(match.group(1))
        last = int(match.group(2)) if match.group(2) is not None else first
        step = int(match.group(3)) if match.group(3) is not None else 1
        if last < first or step < 1:
            raise BakeInputError(f"--frames '{spec}': the range must run forwards (A <= B) with a step of at least 1")
        ranges.append(range(first, last + 1, step))
    count = sum(len(r) for r in ranges)
    if count > MAX_FRAMES:
        raise BakeInputError(f"--frames '{spec}' asks for {count} frames, more than {MAX_FRAMES}")
    if any(r and (r[0] < BLENDER_FRAMES[0] or r[-1] > BLENDER_FRAMES[1]) for r in ranges):
        raise BakeInputError(f"--frames '{spec}': Blender's frames run from {BLENDER_FRAMES[0]} to "
                             f"{BLENDER_FRAMES[1]}")
    return ranges


def parse_frames(spec: str) -> list[int]:
    """The frames of spec (frame_ranges), in the order given; a frame named twice is refused."""
    frames = [frame for r in frame_ranges(spec) for frame in r]
    if len(set(frames)) != len(frames):
        raise BakeInputError(f"--frames '{spec}' names a frame twice")
    return frames


def format_frames(frames: list[int]) -> str:
    """The shortest spelling of frames (in order) as comma-joined runs: [1, 2, 3, 5, 7, 9] ->
    '1-3,5-9:2'. parse_frames(format_frames(f)) == f for any list of distinct frames."""
    items, k = [], 0
    while k < len(frames):
        end = k + 1
        step = frames[end] - frames[k] if end < len(frames) else 1
        if step >= 1:
            while end < len(frames) and frames[end] - frames[end - 1] == step:
                end += 1
        if end - k >= 3 or (end - k == 2 and step == 1):
            items.append(f"{frames[k]}-{frames[end - 1]}" + (f":{step}" if step != 1 else ""))
            k = end
        else:
            items.append(str(frames[k]))
            k += 1
    return ",".join(items)
