# SPDX-License-Identifier: GPL-3.0-or-later
"""``bake --skip-existing``: a re-run (a re-queued farm task, a batch started again) bakes
only what is missing. Every image a bake writes carries a key of what made it (its input
files' contents, the options that change its pixels, the version) in its metadata
(core/imageio.py BAKE_KEY); an output whose file exists with the run's key is finished,
one of other settings or without the key is baked again.
"""
from __future__ import annotations

import hashlib
import json
from dataclasses import replace
from pathlib import Path

from .. import __version__
from ..core.bake.map_kinds import EXTRA_MAPS

# Options that name files or steer the run, not what the pixels are: a farm task and a
# local run of the same bake (other paths, a chunk of the frames) share the key, so their
# files are byte for byte the same.
NOT_IN_KEY = frozenset({"command", "input", "out", "out_dir", "json", "quiet", "skip_existing", "frames",
                        *(kind.option for kind in EXTRA_MAPS), "maps", "gltf_out", "high_poly", "batch_inputs",
                        "batch_outputs", "progress", "manifest", "chunk", "input_root"})


def file_digest(path: Path) -> bytes:
    """sha256 of a file's bytes, read in 1 MiB blocks."""
    digest = hashlib.sha256()
    with open(path, "rb") as fh:
        for block in iter(lambda: fh.read(1 << 20), b""):
            digest.update(block)
    return digest.digest()


def run_key(args, input_files: list[Path]) -> str:
    """The key of a bake: the version, each input file's contents (the input, --high-poly
    files) and every option not in NOT_IN_KEY (--high-poly names of meshes in the input
    count; files count by content)."""
    h = hashlib.blake2b(digest_size=16)
    h.update(__version__.encode())
    for path in input_files:
        h.update(file_digest(path))
    options = {name: value for name, value in vars(args).items() if name not in NOT_IN_KEY}
    # Which maps are written counts, not where; a map not written adds nothing, so a new map
    # row leaves the keys of bakes without it as they were.
    options.update({kind.skip_key: True for kind in EXTRA_MAPS if getattr(args, kind.option, "")})
    options["high_poly_names"] = [spec for spec in args.high_poly or () if not Path(spec).is_file()]
    h.update(json.dumps(options, sort_keys=True, default=str).encode())
    return h.hexdigest()


def skip_finished(request, key: str, report) -> tuple[object | None, list[str]]:
    """(the request left to bake: None when every file is current, the request itself when
    none is, else a copy with only the frames still missing; the summary lines of what was
    skipped). The skipped
    files are listed in report.outputs and report.skipped; a sequence's skipped frames in
    report.frames (with skipped: true)."""
    from ..blender.bake_request import finished_files
    from .io import REPORT
    # The report is written by every run, finished or not: not a file the bake must find.
    wanted = replace(request, extra_outputs=[entry for entry in request.extra_outputs if entry[1] != REPORT])
    if not request.frames:
        done = finished_files(wanted, key)
        if done is None:
            return request, []
        report.outputs.extend(done)
        report.skipped.extend(done)
        return None, [f"hao: skipped {_names(request)}: {_files(len(done))} current, kept"]
    left = []
    for frame in request.frames:
        done = finished_files(wanted, key, frame)
        if done is None:
            left.append(frame)
            continue
        report.skipped.extend(done)
        report.frames.append(dict(frame=frame, seconds=0.0, reused=False, skipped=True, outputs=done))
    if len(left) == len(request.frames):
        return request, []
    lines = [f"hao: skipped {len(request.frames) - len(left)} of {len(request.frames)} frames of "
             f"{_names(request)}: their files are current"]
    if not left:
        report.outputs.extend(path for entry in report.frames for path in entry["outputs"])
        return None, lines
    return replace(request, frames=left), lines


def _files(count: int) -> str:
    return f"{count} file{'s' if count != 1 else ''}"


def _names(request) -> str:
    return ", ".join(f"'{o.name}'" for o in request.targets)
