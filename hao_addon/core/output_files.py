# SPDX-License-Identifier: GPL-3.0-or-later
"""Where a run's files go, checked in one place before any work: no two outputs on one file,
and no output on an input.

Every entry point lists what it will write (maps, UDIM tiles, frames, bent-normal and glTF
sidecars, mesh files, the ``--json`` report, a batch's inputs' maps) as (path, what) pairs and
calls ``check_output_files`` once; a clash is refused naming both parties and the file.
Paths are compared as the file system would resolve them (symbolic links followed, ``..``
removed) and without regard to case: on macOS's and Windows' file systems 'Spot.png' and
'spot.png' are one file, and a farm's outputs move between them.
"""
from __future__ import annotations

import os
from typing import Iterable

from .bake.udim import FIRST_TILE, UDIM_TOKEN
from .errors import BakeInputError

# The tokens of output paths, filled per file: the baked object's (or texture set's) name, the
# input file's name without extension, the frame (zero-padded like Blender's ####). UDIM
# tiles: core/bake/udim.py's <UDIM>.
OBJECT_TOKEN = "{object}"
INPUT_TOKEN = "{input}"
FRAME_TOKEN = "{frame}"
FRAME_DIGITS = 4


# The characters Blender's bpy.path.clean_name replaces with '_' (the same table in every
# supported release): control characters, punctuation but '-' and '_', and Latin-1 but 0xff.
_UNSAFE = [*range(0x00, 0x2d), 0x2e, 0x2f, *range(0x3a, 0x41), *range(0x5b, 0x5f), 0x60, *range(0x7b, 0xff)]
_CLEAN = str.maketrans({code: "_" for code in _UNSAFE})


def clean_name(name: str) -> str:
    """A name as Blender cleans it for file names (bpy.path.clean_name), without bpy: a farm
    job's writer loads no Blender."""
    return name.translate(_CLEAN)


def input_file_name(path: str) -> str:
    """An input file's name without extension as it appears in file names ('{input}'),
    cleaned as object names are."""
    return clean_name(os.path.splitext(os.path.basename(path))[0])


class OutputCollision(BakeInputError):
    """Two outputs on one file, or an output on an input file; parties: the two whats."""

    def __init__(self, message: str, parties: tuple[str, str]) -> None:
        super().__init__(message)
        self.parties = parties


def example_path(path: str, frame: int = 0) -> str:
    """The path with every token filled by an example value ('{object}' -> 'object', <UDIM> ->
    1001, '{frame}' -> the frame given, zero-padded: the sequence's first), for checking
    before a bake that such a file can be written."""
    return (path.replace(OBJECT_TOKEN, "object").replace(UDIM_TOKEN, str(FIRST_TILE))
            .replace(FRAME_TOKEN, f"{frame:0{FRAME_DIGITS}d}"))


def frame_pattern(path: str) -> str:
    """A sequence's path as Blender shows one: '{frame}' as '####' (FRAME_DIGITS of them)."""
    return path.replace(FRAME_TOKEN, "#" * FRAME_DIGITS)


def with_token(path: str, token: str) -> str:
    """path with token in it: as it is, or with '_' + token added before the extension
    ('ao.png', '{frame}' -> 'ao_{frame}.png')."""
    if token in path:
        return path
    stem, ext = os.path.splitext(path)
    return f"{stem}_{token}{ext}"


def frame_file(path: str, frame: int) -> str:
    """path with its '{frame}' filled: the frame zero-padded to FRAME_DIGITS (Blender's ####)."""
    return path.replace(FRAME_TOKEN, f"{frame:0{FRAME_DIGITS}d}")


def file_key(path: str, _folders: dict[str, str] | None = None) -> str:
    """The identity of the file a path names: its folder resolved (links followed), then the
    name, case-folded. _folders caches resolved folders (thousands of frame files share one)."""
    folder, name = os.path.split(os.path.abspath(path))
    if _folders is None:
        resolved = os.path.realpath(folder)
    else:
        resolved = _folders.get(folder)
        if resolved is None:
            resolved = _folders[folder] = os.path.realpath(folder)
    full = os.path.join(resolved, name)
    if os.path.islink(full):  # an output that is a link to another file writes that file
        full = os.path.realpath(full)
    return os.path.normcase(full).casefold()


def check_output_files(outputs: Iterable[tuple[str, str]], inputs: Iterable[tuple[str, str]] = ()) -> int:
    """Raise OutputCollision if two outputs name one file, or an output names an input.
    outputs, inputs: (path, what) pairs, what a phrase such as "the AO map of 'Spot'" or
    "the report (--json)". Empty paths and '-' (standard output) are skipped. Returns the
    number of output files checked."""
    folders: dict[str, str] = {}
    read = {file_key(path, folders): (path, what) for path, what in inputs if path and path != "-"}
    claimed: dict[str, tuple[str, str]] = {}
    for path, what in outputs:
        if not path or path == "-":
            continue
        key = file_key(path, folders)
        if key in read:
            raise OutputCollision(f"{what} would overwrite {read[key][1]} ('{read[key][0]}'): choose another name",
                                  (what, read[key][1]))
        if key in claimed:
            first = claimed[key][1]
            raise OutputCollision(f"{first} and {what} would both be written to '{path}': give them "
                                  f"different names" if first != what else
                                  f"{what} would be written to '{path}' twice", (first, what))
        claimed[key] = (path, what)
    return len(claimed)
