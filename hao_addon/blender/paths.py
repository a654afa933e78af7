# SPDX-License-Identifier: GPL-3.0-or-later
"""Output paths as Blender users write them: '//' relative to the .blend file, '{object}'."""
from __future__ import annotations

import bpy

from ..core.errors import BakeInputError
# The path helpers without Blender (tokens, example paths, frame patterns) are core/output_files.py's.
from ..core.output_files import FRAME_TOKEN, OBJECT_TOKEN, example_path, frame_pattern  # noqa: F401 - re-exported


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

