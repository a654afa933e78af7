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

MANIFEST_VERSION = 2
# The most inputs (or frames) one task takes: a larger chunk is a typo, not a job.
MAX_CHUNK_SIZE = 1_000_000
# The folder in the output folder where each task's report (its receipt: which files it
# wrote for which input) lands; Verify reads them.
RECEIPTS = ".hao-job"


@dataclass(frozen=True)
class Manifest:
    """root: the folder the inputs are relative to (absolute, as written; a task gets it as
    --input-root, path-mapped); entries: input paths relative to root, '/'-separated;
    chunk_size: inputs (or frames) per task; out: the output file name in the output folder
    ('{input}_ao.png'); frames: a frame range (OpenJD syntax) of the one input, or '';
    outputs: every file name (template) a task writes per input in the output folder, the
    map first ('{input}_ao.png', '{input}_ao_thickness.png', ...): what Verify expects."""

    root: str
    entries: tuple[str, ...]
    chunk_size: int
    out: str
    frames: str = ""
    outputs: tuple[str, ...] = ()
    version: int = MANIFEST_VERSION

    def receipt(self, chunk: int) -> str:
        """The report file of task `chunk`, relative to the output folder."""
        return f"{RECEIPTS}/chunk-{chunk}.json"

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
        data["outputs"] = list(self.outputs)
        return json.dumps(data, indent=1) + "\n"


def make_manifest(inputs: list[str], chunk_size: int, out: str, frames: str = "",
                  outputs: tuple[str, ...] = ()) -> Manifest:
    """The manifest of input files (their common folder as root; each entry relative to it)."""
    if not 1 <= chunk_size <= MAX_CHUNK_SIZE:
        raise BakeInputError(f"--chunk-size must be at least 1 and at most {MAX_CHUNK_SIZE}, got {chunk_size}")
    if frames and len(inputs) != 1:
        raise BakeInputError("a farm job over --frames bakes one input, its frames in chunks: give one input")
    paths = [os.path.abspath(p) for p in inputs]
    root = os.path.commonpath([os.path.dirname(p) for p in paths])
    entries = tuple(Path(os.path.relpath(p, root)).as_posix() for p in paths)
    if len(set(entries)) != len(entries):
        raise BakeInputError("an input is named twice")
    manifest = Manifest(root, entries, chunk_size, out, frames, tuple(outputs or (out,)))
    manifest.chunk_count  # noqa: B018 - the frame range is checked here (count, syntax)
    return manifest


def read_manifest(path: str | Path) -> Manifest:
    """A manifest written by Manifest.to_json, its whole shape checked before anything uses
    it; BakeInputError naming the first fault for anything else (nothing is written)."""
    try:
        data = json.loads(Path(path).read_text(encoding="utf-8"))
    except (OSError, ValueError) as exc:
        raise BakeInputError(f"cannot read the manifest '{path}': {exc}") from None
    fault = manifest_fault(data)
    if fault:
        raise BakeInputError(f"the manifest '{path}' is not a job manifest of this hao: {fault}")
    manifest = Manifest(data["root"], tuple(data["entries"]), data["chunk_size"], data["out"], data["frames"],
                        tuple(data["outputs"]))
    try:
        manifest.chunk_count  # noqa: B018 - the frame range's syntax and size
    except BakeInputError as exc:
        raise BakeInputError(f"the manifest '{path}' has a bad frame range: {exc}") from None
    return manifest


# The manifest's fields and their kinds, as Manifest.to_json writes them.
FIELDS = {"version": int, "root": str, "entries": list, "chunk_size": int, "out": str, "frames": str,
          "outputs": list}


def manifest_fault(data) -> str:
    """'' for a manifest's JSON of the right shape, else what is wrong (the first fault)."""
    if not isinstance(data, dict):
        return f"expected an object, found {type(data).__name__}"
    if data.get("version") != MANIFEST_VERSION:
        return f"version {data.get('version')!r}, this hao reads {MANIFEST_VERSION}"
    for name, kind in FIELDS.items():
        if name not in data:
            return f"'{name}' is missing"
        if not isinstance(data[name], kind) or isinstance(data[name], bool):
            return f"'{name}' must be {'a whole number' if kind is int else 'a list' if kind is list else 'text'}, " \
                   f"found {json.dumps(data[name])[:40]}"
    unknown = sorted(set(data) - set(FIELDS))
    if unknown:
        return f"unknown field '{unknown[0]}'"
    if not 1 <= data["chunk_size"] <= MAX_CHUNK_SIZE:
        return f"'chunk_size' must be between 1 and {MAX_CHUNK_SIZE}, found {data['chunk_size']}"
    if not data["entries"]:
        return "'entries' is empty"
    for name in ("root", "out", "frames"):
        bad = text_fault(data[name])
        if bad:
            return f"'{name}' {bad}"
    if not os.path.isabs(data["root"]):
        return "'root' must be an absolute folder"
    for field_name in ("entries", "outputs"):
        for value in data[field_name]:
            if not isinstance(value, str) or not value:
                return f"'{field_name}' must hold non-empty text, found {json.dumps(value)[:40]}"
            bad = text_fault(value) or _relative_fault(value)
            if bad:
                return f"'{field_name}' entry {json.dumps(value)[:60]} {bad}"
    if not data["out"] or os.path.dirname(data["out"]):
        return "'out' must be a file name"
    if len(set(data["entries"])) != len(data["entries"]):
        return "an input is named twice in 'entries'"
    return ""


def text_fault(value: str) -> str:
    """'' for text that can travel in any farm's command line or file, else what is wrong:
    control characters (a newline splits a command file's line, NUL ends a C string)."""
    for char in value:
        if ord(char) < 32 or ord(char) == 127:
            return f"contains a control character ({_char_name(char)})"
    return ""


def _char_name(char: str) -> str:
    return {"\n": "a newline", "\r": "a carriage return", "\t": "a tab", "\0": "NUL"}.get(char, f"U+{ord(char):04X}")


def _relative_fault(value: str) -> str:
    parts = value.split("/")
    if value.startswith("/") or "\\" in value or ".." in parts or "" in parts:
        return "must be a path relative to its folder, '/'-separated, without '..'"
    return ""
