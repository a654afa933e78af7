# SPDX-License-Identifier: GPL-3.0-or-later
"""Where a Re-bake Changed finds the last bake of a map, and where a bake leaves it: in this
Blender session's memory (the panel's bakes, the last REMEMBERED_MAPS maps) and in a record
file beside the map (hao_addon/rebake.record_path: the command line's --rebake-changed, and
the panel's when the map has a file). The re-bake itself is hao_addon/rebake.py's."""
from __future__ import annotations

from collections import OrderedDict
from pathlib import Path
from typing import Generator

from ..bake import BakeResult
from ..core.bake.scene_changes import SceneState
from ..bake import bake_steps
from ..rebake import read_record, record, record_bytes, record_path, rebake_steps
from .bake_request import output_path_for

# Maps a session keeps for Re-bake Changed (each its float map, masks, twins and kept bounds:
# 56 MB at 2048^2, 224 MB at 4096^2).
REMEMBERED_MAPS = 4
_remembered: OrderedDict[tuple[str, str], tuple[BakeResult, SceneState]] = OrderedDict()


def previous_bake(label: str, path: str) -> tuple[BakeResult | None, SceneState | None]:
    """(the last bake of label's map at path ('' without a file), its scene's state): this
    session's, else the record beside the file; (None, None) when there is none (or it is
    unreadable: the re-bake is then full, and says why)."""
    if (label, path) in _remembered:
        return _remembered[label, path]
    record = Path(record_path(path)) if path else None
    if record is not None and record.is_file():
        found = read_record(record.read_bytes())
        if found is not None:
            return found
    return None, None


def remember(label: str, path: str, result: BakeResult, state: SceneState) -> None:
    """Keep the bake of label's map for this session's next Re-bake Changed."""
    _remembered[label, path] = (result, state)
    _remembered.move_to_end((label, path))
    while len(_remembered) > REMEMBERED_MAPS:
        _remembered.popitem(last=False)


def remembered_any() -> bool:
    """Whether this session keeps a bake to re-bake from."""
    return bool(_remembered)


def is_remembered(label: str, path: str) -> bool:
    """Whether this session keeps the bake of label's map at path."""
    return (label, path) in _remembered


def forget_all() -> None:
    """Drop every remembered bake (unregistering the add-on, tests)."""
    _remembered.clear()


def keeps_records(request, frame: int | None) -> bool:
    """Whether a job's bake re-bakes what changed or keeps its scene's state for that (one
    frame's image bake, with Re-bake Changed or for the panel: request.remember)."""
    return frame is None and request.kind.writes_images and (request.options.rebake_changed or request.remember)


def recorded_steps(request, unit, target, occluders: list, settings, records: dict
                   ) -> Generator[float, None, BakeResult]:
    """The unit's bake (re-baking only what changed where request asks) with its scene's
    state, kept in records (label -> (map path, bake, state)) until the job commits."""
    path = output_path_for(request, unit.objects[0])
    if request.options.rebake_changed:
        previous, before = previous_bake(unit.label, path)
        result, state, _report = yield from rebake_steps(previous, before, target, occluders, settings)
    else:
        result = yield from bake_steps(target, occluders, settings)
        state = record(target.soup, occluders, settings)
    records[unit.label] = (path, result, state)
    return result


def stage_records(staged, request, records: dict) -> None:
    """Stage each map's record beside its file (Re-bake Changed on a map with a file)."""
    for path, result, state in records.values():
        if path and request.options.rebake_changed:
            staged.write_bytes(record_path(path), record_bytes(state, result))


def remember_records(request, records: dict) -> None:
    """Keep the job's bakes in this session's memory (request.remember: the panel)."""
    if request.remember:
        for label, (path, result, state) in records.items():
            remember(label, path, result, state)
