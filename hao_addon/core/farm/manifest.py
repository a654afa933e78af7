# SPDX-License-Identifier: GPL-3.0-or-later
"""A farm job's manifest: its inputs relative to one root folder (so a farm's path mapping
rewrites the root alone), how many go into one task, and the output file names; with a
frame range instead, one input whose frames are chunked.

A task names its chunk by number; ``chunk_inputs`` and ``chunk_frames`` give what it bakes,
so job descriptions stay the same size for 10 inputs or 100,000 (an OpenJD list holds at
most 1,024 values; a chunk number comes from an INT range).
"""
from __future__ import annotations

import json
import os
from dataclasses import asdict, dataclass
from pathlib import Path

from ..errors import BakeInputError
from ..frame_ranges import format_frames, parse_frames

MANIFEST_VERSION = 1


@dataclass(frozen=True)
class Manifest:
    """root: the folder the inputs are relative to (absolute, as written; a task gets it as
    --input-root, path-mapped); entries: input paths relative to root, '/'-separated;
    chunk_size: inputs (or frames) per task; out: the output file name in the output folder
    ('{input}_ao.png'); frames: a frame range (OpenJD syntax) of the one input, or ''."""

    root: str
    entries: tuple[str, ...]
    chunk_size: int
    out: str
    frames: str = ""
    version: int = MANIFEST_VERSION

    @property
    def chunk_count(self) -> int:
        count = len(parse_frames(self.frames)) if self.frames else len(self.entries)
        return -(-count // self.chunk_size)

    def chunk_inputs(self, chunk: int) -> list[str]:
        """The entries of task `chunk` (the one input of a frame range, for every chunk)."""
        self._check(chunk)
        if self.frames:
            return list(self.entries)
        return list(self.entries[chunk * self.chunk_size:(chunk + 1) * self.chunk_size])

    def chunk_frames(self, chunk: int) -> str:
        """The frames of task `chunk` in range syntax ('' without a frame range)."""
        self._check(chunk)
        if not self.frames:
            return ""
        return format_frames(parse_frames(self.frames)[chunk * self.chunk_size:(chunk + 1) * self.chunk_size])

    def _check(self, chunk: int) -> None:
        if not 0 <= chunk < self.chunk_count:
            raise BakeInputError(f"chunk {chunk} is not in this job: it has chunks 0 to {self.chunk_count - 1}")

    def to_json(self) -> str:
        data = asdict(self)
        data["entries"] = list(self.entries)
        return json.dumps(data, indent=1) + "\n"


def make_manifest(inputs: list[str], chunk_size: int, out: str, frames: str = "") -> Manifest:
    """The manifest of input files (their common folder as root; each entry relative to it)."""
    if chunk_size < 1:
        raise BakeInputError(f"--chunk-size must be at least 1, got {chunk_size}")
    if frames and len(inputs) != 1:
        raise BakeInputError("a farm job over --frames bakes one input, its frames in chunks: give one input")
    paths = [os.path.abspath(p) for p in inputs]
    root = os.path.commonpath([os.path.dirname(p) for p in paths])
    entries = tuple(Path(os.path.relpath(p, root)).as_posix() for p in paths)
    if len(set(entries)) != len(entries):
        raise BakeInputError("an input is named twice")
    manifest = Manifest(root, entries, chunk_size, out, frames)
    manifest.chunk_count  # noqa: B018 - the frame range is checked here (count, syntax)
    return manifest


def read_manifest(path: str | Path) -> Manifest:
    """A manifest written by Manifest.to_json; BakeInputError for anything else."""
    try:
        data = json.loads(Path(path).read_text())
        if data.get("version") != MANIFEST_VERSION:
            raise BakeInputError(f"'{path}' is a manifest of version {data.get('version')}, this hao reads "
                                 f"{MANIFEST_VERSION}")
        return Manifest(str(data["root"]), tuple(data["entries"]), int(data["chunk_size"]), str(data["out"]),
                        str(data.get("frames", "")))
    except (OSError, ValueError, KeyError, TypeError) as exc:
        raise BakeInputError(f"cannot read the manifest '{path}': {exc}") from None
