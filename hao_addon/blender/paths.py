# SPDX-License-Identifier: GPL-3.0-or-later
"""Output paths as Blender users write them: '//' relative to the .blend file, '{object}'."""
from __future__ import annotations

import bpy

from ..core.errors import BakeInputError
from ..core.output_files import FRAME_DIGITS, FRAME_TOKEN, OBJECT_TOKEN  # noqa: F401 - this module's names too
from ..core.output_files import input_file_name  # noqa: F401 - this module's name too


def example_path(path: str, frame: int = 0) -> str:
    """The path with every token filled by an example value ('{object}' -> 'object', <UDIM> ->
    1001, '{frame}' -> the frame given, zero-padded: the sequence's first), for checking
    before a bake that such a file can be written."""
    from ..core.bake.udim import FIRST_TILE, UDIM_TOKEN
    return (path.replace(OBJECT_TOKEN, "object").replace(UDIM_TOKEN, str(FIRST_TILE))
            .replace(FRAME_TOKEN, f"{frame:0{FRAME_DIGITS}d}"))


def frame_pattern(path: str) -> str:
    """A sequence's path as Blender shows one: '{frame}' as '####' (FRAME_DIGITS of them)."""
    return path.replace(FRAME_TOKEN, "#" * FRAME_DIGITS)


def absolute_path(path: str) -> str:
    """Blender's abspath, refusing '//' paths while the .blend file has no location (they would
    silently land in the process's working directory)."""
    if path.startswith("//") and not bpy.data.filepath:
        raise BakeInputError(f"'{path}' is relative to the .blend file ('//'), which is not saved yet: "
                             f"save the file first or give an absolute path")
    return bpy.path.abspath(path)


def object_file_name(obj) -> str:
    """The object's name as it appears in file names (Blender's clean_name)."""
    return bpy.path.clean_name(obj.name)

