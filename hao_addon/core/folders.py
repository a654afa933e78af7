# SPDX-License-Identifier: GPL-3.0-or-later
"""Output folders made on demand, as Blender's `-o` and most batch tools make them.

A path is checked before any work (`unmakeable_reason`: only what cannot be created is
refused) and its missing folders are made when the first file goes there (`make_folders`),
so a run refused as bad input leaves nothing behind; a write that fails removes the folders
it made (`remove_made`).
"""
from __future__ import annotations

import os
from pathlib import Path


def nearest_existing(folder: Path) -> Path:
    """The folder itself, or its nearest ancestor that exists (a folder or not)."""
    folder = Path(os.path.abspath(folder))
    while not os.path.lexists(folder) and folder.parent != folder:
        folder = folder.parent
    return folder


def unmakeable_reason(folder: str | Path) -> str | None:
    """None when folder exists or can be made; otherwise why not ("'a/b' is a file",
    "permission denied in 'a'")."""
    folder = Path(os.path.abspath(folder))
    if folder.is_dir():
        return None
    base = nearest_existing(folder)
    if not base.is_dir():
        return f"'{base}' is a file, not a folder"
    if not os.access(base, os.W_OK | os.X_OK):
        return f"permission denied in '{base}'"
    return None


def make_folders(folder: str | Path) -> list[Path]:
    """Make folder and its missing parents; returns those made, outermost first."""
    folder = Path(os.path.abspath(folder))
    missing = []
    probe = folder
    while not os.path.lexists(probe) and probe.parent != probe:
        missing.append(probe)
        probe = probe.parent
    made = []
    for path in reversed(missing):
        try:
            os.mkdir(path)
        except FileExistsError:  # made by a concurrent task: theirs, not ours to remove
            continue
        made.append(path)
    return made


def remove_made(made: list[Path]) -> None:
    """Remove the folders make_folders made, innermost first, where they are still empty."""
    for path in reversed(made):
        try:
            os.rmdir(path)
        except OSError:
            pass
