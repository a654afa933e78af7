# SPDX-License-Identifier: GPL-3.0-or-later
"""A Flamenco job type: a JavaScript job compiler script (Flamenco Manager's scripts/
folder) whose compileJob makes one task per chunk of the manifest, each an 'exec' command
of the same bake command line as the OpenJD tasks, and a 'verify' task after them; and
the job's settings (job.json) to submit it with.

The command lists come from tasks.py with placeholders ('{executable}', '{chunk}', ...)
that the script fills from the job's settings, so a Flamenco task runs exactly what an
OpenJD task runs. A python runner's PYTHONPATH goes through 'env' (exec has no
environment of its own).
"""
from __future__ import annotations

import json

from .manifest import Manifest
from .tasks import TaskValues, bake_task, verify_task

SCRIPT_NAME = "hao_bake.js"
JOB_TYPE = "hao-ao-bake"
# The job settings the script reads (keys), each a placeholder in the command lists.
SETTINGS = ("executable", "manifest", "input_root", "out_dir", "addon")


def _placeholders(chunk: str) -> TaskValues:
    return TaskValues(*(f"{{{key}}}" for key in SETTINGS[:4]), chunk=chunk)


def _with_env(runner: str, args: list[str]) -> list[str]:
    return ["env", "PYTHONPATH={addon}", *args] if runner == "python" else args


def literal(text: str) -> str:
    """text as the script's command templates hold it: braces doubled, so a '{' in a path or
    option stays itself instead of reading as one of the job's placeholders."""
    return text.replace("{", "{{").replace("}", "}}")


def job_type_script(manifest: Manifest, runner: str, bake_options: list[str], name: str, version: str) -> str:
    """The job compiler script (JavaScript) of this job's manifest and options."""
    bake = _with_env(runner, bake_task(runner, _placeholders("{chunk}"), [literal(o) for o in bake_options]))
    verify = _with_env(runner, verify_task(runner, _placeholders("")))
    settings = [{"key": key, "type": "string", "required": key != "addon" or runner == "python",
                 **({"subtype": "dir_path"} if key in ("input_root", "out_dir", "addon") else
                    {"subtype": "file_path"} if key == "manifest" else {})} for key in SETTINGS]
    return f"""// SPDX-License-Identifier: GPL-3.0-or-later
// Written by hao {version} ('hao farm flamenco'): a Flamenco job type that bakes AO in
// {manifest.chunk_count} tasks of the manifest {json.dumps(manifest.root)}/..., then verifies the outputs.
// Put it in Flamenco Manager's scripts/ folder; submit job.json's settings with it.

const HAO_CHUNKS = {manifest.chunk_count};
const HAO_BAKE = {json.dumps(bake)};
const HAO_VERIFY = {json.dumps(verify)};

const JOB_TYPE = {{
    label: {json.dumps(name)},
    description: "HAO ambient occlusion bake, one task per chunk of its manifest",
    settings: {json.dumps(settings)},
}};

// A command list with the job's settings (and the chunk) in place of the placeholders;
// '{{{{' and '}}}}' stand for a literal brace (a path or an option may hold one).
function haoArgs(template, settings, chunk) {{
    return template.map((arg) => arg.replace(/\\{{\\{{|\\}}\\}}|\\{{(\\w+)\\}}/g, (whole, key) =>
        whole === "{{{{" ? "{{" : whole === "}}}}" ? "}}" :
        key === "chunk" ? String(chunk) : (key in settings ? String(settings[key]) : whole)));
}}

function haoExec(args) {{
    return author.Command("exec", {{ exe: args[0], args: args.slice(1) }});
}}

function compileJob(job) {{
    const settings = job.settings;
    const bakes = [];
    for (let chunk = 0; chunk < HAO_CHUNKS; chunk++) {{
        const task = author.Task(`bake-${{chunk}}`, "misc");
        task.addCommand(haoExec(haoArgs(HAO_BAKE, settings, chunk)));
        job.addTask(task);
        bakes.push(task);
    }}
    const verify = author.Task("verify", "misc");
    verify.addCommand(haoExec(haoArgs(HAO_VERIFY, settings, "")));
    for (const task of bakes) {{
        verify.addDependency(task);
    }}
    job.addTask(verify);
}}
"""


def job_settings(values: dict[str, str], name: str) -> dict:
    """job.json: the job to submit (Flamenco's SubmittedJob: name, type, settings)."""
    return {"name": name, "type": JOB_TYPE, "priority": 50, "submitter_platform": "linux",
            "settings": {key: values[key] for key in SETTINGS if key in values}}
