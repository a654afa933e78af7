# SPDX-License-Identifier: GPL-3.0-or-later
"""An OpenCue job as a cuecmd command file: one line per task (a chunk of the manifest, the
same bake command as the OpenJD tasks, with the paths as given), then the verify line;
``cuecmd hao_commands.txt --chunk 1`` submits one frame per line. cuecmd runs every line
in one layer, so the verify line is last and is run once the bakes before it are done
when the layer runs in order (--chunk 1, one core), or on its own after the job."""
from __future__ import annotations

import shlex

from .manifest import Manifest
from .tasks import TaskValues, bake_task, verify_task

COMMANDS_NAME = "hao_commands.txt"


def task_lines(manifest: Manifest, runner: str, bake_options: list[str], values: dict[str, str]) -> list[list[str]]:
    """The commands of the job: every chunk's bake, then the verify."""
    prefix = ["env", f"PYTHONPATH={values['addon']}"] if runner == "python" else []

    def task(chunk: str) -> TaskValues:
        return TaskValues(values["executable"], values["manifest"], values["input_root"], values["out_dir"], chunk)
    bakes = [prefix + bake_task(runner, task(str(k)), bake_options) for k in range(manifest.chunk_count)]
    return bakes + [prefix + verify_task(runner, task(""))]


def command_file(manifest: Manifest, runner: str, bake_options: list[str], values: dict[str, str]) -> str:
    """The cuecmd command file (shell-quoted lines)."""
    lines = [shlex.join(args) for args in task_lines(manifest, runner, bake_options, values)]
    return "\n".join(lines) + "\n"
