# SPDX-License-Identifier: GPL-3.0-or-later
"""The commands a farm task runs: the workstation's own command line, over one chunk of a
manifest. Every job format (OpenJD, Flamenco, OpenCue) builds its tasks from these lists,
with its own placeholders for the values a farm fills in (paths after path mapping, the
chunk number), so every farm runs the same command."""
from __future__ import annotations

from dataclasses import dataclass

from .manifest import RECEIPTS

# How a worker runs hao: the executable's arguments before hao's own.
RUNNERS = {
    "blender": ("-b", "-c", "hao"),  # a Blender with the extension installed (blender -b -c hao bake ...)
    "python": ("-m", "hao_addon"),  # a Python with the bpy wheel, the add-on's folder on PYTHONPATH
}
# Farm tasks print their progress in Open Job Description's form (openjd_progress: P).
PROGRESS_FORMAT = "openjd"


@dataclass(frozen=True)
class TaskValues:
    """What a task command is made of; a job format passes its placeholders for the values
    the farm fills in ('{{Param.InputRoot}}', '${chunk}', ...) or the values themselves."""

    executable: str
    manifest: str
    input_root: str
    out_dir: str
    chunk: str


def bake_task(runner: str, values: TaskValues, bake_options: list[str]) -> list[str]:
    """[executable, arguments...] of one chunk's bake: only what is missing is baked
    (--skip-existing), so a re-queued task redoes just that. Its report (--json) is the
    task's receipt in the output folder (manifest.RECEIPTS): the files it wrote for each
    input, which Verify checks. Values as '--option=value': a path that starts with '-'
    stays a value."""
    return [values.executable, *RUNNERS[runner], "bake", f"--manifest={values.manifest}", f"--chunk={values.chunk}",
            f"--input-root={values.input_root}", f"--out-dir={values.out_dir}", "--skip-existing",
            f"--progress={PROGRESS_FORMAT}", f"--json={values.out_dir}/{RECEIPTS}/chunk-{values.chunk}.json",
            *bake_options]


def verify_task(runner: str, values: TaskValues) -> list[str]:
    """[executable, arguments...] of the check that every expected output exists and is whole."""
    return [values.executable, *RUNNERS[runner], "farm", "verify", f"--manifest={values.manifest}",
            f"--out-dir={values.out_dir}"]
