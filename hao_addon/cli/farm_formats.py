# SPDX-License-Identifier: GPL-3.0-or-later
"""The job formats ``hao farm`` writes, as a table (FORMATS: each format's help and its files'
writer), and the ``farm`` subcommands' options. Below both the parser (which adds these
options) and the farm command (cli/farm.py, which writes the files)."""
from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path

from .. import __version__
from ..core.farm import flamenco, openjd, opencue
from ..core.farm.manifest import Manifest
from ..core.farm.tasks import RUNNERS


@dataclass(frozen=True)
class Job:
    """What a job's files are made of (every format takes the same)."""

    manifest: Manifest
    runner: str
    options: list  # the bake options, forwarded
    values: dict  # the job's paths and executable: keys as openjd.PARAM's
    name: str
    extra_inputs: list  # --high-poly files, uploaded with the inputs


def _openjd_files(job: Job) -> dict[str, str]:
    params = {k: job.values[k] for k in openjd.PARAM if k in job.values}
    return {"template.json": _json(openjd.job_template(job.manifest, job.runner, job.options, job.name, __version__)),
            "parameter_values.json": _json(openjd.parameter_values(params)),
            "job_parameters.json": _json(openjd.job_parameters(params)),
            "asset_references.json": _json(openjd.asset_references(job.manifest, job.values["manifest"],
                                                                   job.values["out_dir"], job.extra_inputs))}


def _flamenco_files(job: Job) -> dict[str, str]:
    return {flamenco.SCRIPT_NAME: flamenco.job_type_script(job.manifest, job.runner, job.options, job.name,
                                                           __version__),
            "job.json": _json(flamenco.job_settings(job.values, job.name))}


def _opencue_files(job: Job) -> dict[str, str]:
    return {opencue.COMMANDS_NAME: opencue.command_file(job.manifest, job.runner, job.options, job.values)}


def _json(data) -> str:
    return json.dumps(data, indent=2) + "\n"


# The formats `farm` writes: (help, the job's files {name: text} besides manifest.json).
FORMATS = {
    "openjd": ("an Open Job Description job bundle (AWS Deadline Cloud; 'openjd run' runs it locally)", _openjd_files),
    "flamenco": ("a Flamenco job type (JavaScript) and the job's settings", _flamenco_files),
    "opencue": ("an OpenCue command file for cuecmd, one line per task", _opencue_files),
}
# farm's own options (and the outputs the manifest carries): not forwarded to the tasks.
FARM_OWN = frozenset({"command", "farm_command", "input", "out", "out_dir", "frames", "skip_existing", "json",
                      "quiet", "bundle", "chunk_size", "runner", "executable", "addon_path", "name", "help"})
DEFAULT_CHUNK = 10
# The folder holding hao_addon: a python runner's PYTHONPATH.
ADDON_FOLDER = str(Path(__file__).resolve().parent.parent.parent)


def add_farm_parsers(sub, add_bake_arguments, add_run_options) -> None:
    farm = sub.add_parser("farm", help="write a bake job for a render farm (OpenJD, Flamenco, OpenCue)")
    kinds = farm.add_subparsers(dest="farm_command", required=True)
    for name, (text, _writer) in FORMATS.items():
        p = kinds.add_parser(name, help=f"write {text}")
        add_bake_arguments(p)
        p.add_argument("--bundle", required=True, metavar="DIR", help="the folder to write the job into")
        p.add_argument("--chunk-size", type=int, default=DEFAULT_CHUNK, metavar="N",
                       help=f"inputs (or frames of --frames) per task (default {DEFAULT_CHUNK})")
        p.add_argument("--runner", choices=tuple(RUNNERS), default="blender",
                       help="how a worker runs hao: blender (a Blender with the extension: blender -b -c hao "
                            "bake ...; default) or python (a Python with the bpy wheel: PATH -m hao_addon bake ...)")
        p.add_argument("--executable", default=None, metavar="PATH",
                       help="the runner's executable on the workers (a job parameter; default: 'blender', or this "
                            "Python for --runner python)")
        p.add_argument("--addon-path", default=ADDON_FOLDER, metavar="DIR",
                       help="--runner python: the folder holding hao_addon on the workers (default: this one)")
        p.add_argument("--name", default="HAO AO bake", help="the job's name")
        add_run_options(p)
    v = kinds.add_parser("verify", help="a job's last step: fail, naming them, if expected outputs are missing")
    v.add_argument("--manifest", required=True, metavar="FILE")
    v.add_argument("--out-dir", required=True, metavar="DIR")
    add_run_options(v)
