# SPDX-License-Identifier: GPL-3.0-or-later
"""An Open Job Description job bundle (the job template AWS Deadline Cloud runs, and
``openjd run`` runs locally): template.json (jobtemplate-2023-09), parameter_values.json,
asset_references.json, beside the job's manifest.json, and job_parameters.json (the
parameter values as ``openjd run --job-param file://`` takes them). JSON, not YAML: Blender's Python
has no PyYAML, and OpenJD reads either.

Step Bake has one task per chunk of the manifest (an INT range, so any number of chunks);
step Verify, after it, fails naming any expected output that is missing, empty or broken. The
paths are PATH job parameters (input root IN, output folder OUT, manifest IN, executable),
so a farm's path mapping rewrites them.
"""
from __future__ import annotations

from .manifest import Manifest
from .tasks import TaskValues, bake_task, verify_task

TEMPLATE_VERSION = "jobtemplate-2023-09"
PARAM = {"executable": "Executable", "manifest": "Manifest", "input_root": "InputRoot", "out_dir": "OutputDir",
         "addon": "AddonPath"}
CHUNK_PARAM = "Chunk"
# A stopped task gets SIGTERM first (hao exits 143 within a second, nothing half-written).
CANCELATION = {"mode": "NOTIFY_THEN_TERMINATE", "notifyPeriodInSeconds": 30}


def _values(chunk: str) -> TaskValues:
    return TaskValues(*(f"{{{{Param.{PARAM[name]}}}}}" for name in ("executable", "manifest", "input_root",
                                                                   "out_dir")), chunk=chunk)


def _action(args: list[str]) -> dict:
    return {"command": args[0], "args": args[1:], "cancelation": CANCELATION}


def job_template(manifest: Manifest, runner: str, bake_options: list[str], name: str, version: str) -> dict:
    """The job template: parameters, the Bake step (a task per chunk) and Verify."""
    path = {"type": "PATH"}
    parameters = [
        {"name": PARAM["input_root"], **path, "objectType": "DIRECTORY", "dataFlow": "IN",
         "description": "the folder the manifest's inputs are relative to"},
        {"name": PARAM["out_dir"], **path, "objectType": "DIRECTORY", "dataFlow": "OUT",
         "description": "where the maps are written"},
        {"name": PARAM["manifest"], **path, "objectType": "FILE", "dataFlow": "IN",
         "description": "the job's inputs and chunks (manifest.json of the bundle)"},
        {"name": PARAM["executable"], **path, "objectType": "FILE",
         "description": f"the {'Blender' if runner == 'blender' else 'Python (with the bpy wheel)'} that runs hao"},
    ]
    environments = []
    if runner == "python":  # the add-on's folder on the worker, for '-m hao_addon'
        parameters.append({"name": PARAM["addon"], **path, "objectType": "DIRECTORY", "dataFlow": "IN",
                           "description": "the folder holding hao_addon"})
        environments.append({"name": "HaoAddon", "variables": {"PYTHONPATH": f"{{{{Param.{PARAM['addon']}}}}}"}})
    bake = {"name": "Bake",
            "parameterSpace": {"taskParameterDefinitions": [
                {"name": CHUNK_PARAM, "type": "INT", "range": f"0-{manifest.chunk_count - 1}"}]},
            "script": {"actions": {"onRun": _action(bake_task(runner, _values(f"{{{{Task.Param.{CHUNK_PARAM}}}}}"),
                                                              bake_options))}}}
    verify = {"name": "Verify", "dependencies": [{"dependsOn": "Bake"}],
              "script": {"actions": {"onRun": _action(verify_task(runner, _values("")))}}}
    template = {"specificationVersion": TEMPLATE_VERSION, "name": name,
                "description": f"HAO AO bake (hao {version}): {len(manifest.entries)} inputs"
                               + (f", frames {manifest.frames}" if manifest.frames else "")
                               + f", {manifest.chunk_count} tasks",
                "parameterDefinitions": parameters, "steps": [bake, verify]}
    if environments:
        template["jobEnvironments"] = environments
    return template


def parameter_values(values: dict[str, str]) -> dict:
    """parameter_values.json, as Deadline Cloud reads a bundle's: the job parameters' values
    (values' keys as PARAM's)."""
    return {"parameterValues": [{"name": PARAM[key], "value": value} for key, value in values.items()]}


def job_parameters(values: dict[str, str]) -> dict:
    """job_parameters.json: the same values as 'openjd run --job-param file://...' reads them."""
    return {PARAM[key]: value for key, value in values.items()}


def asset_references(manifest: Manifest, manifest_path: str, out_dir: str, extra_inputs: list[str]) -> dict:
    """asset_references.json: the files a submission uploads (the inputs, the manifest, the
    --high-poly files) and the folder it downloads."""
    inputs = [f"{manifest.root}/{entry}" for entry in manifest.entries] + [manifest_path, *extra_inputs]
    return {"assetReferences": {"inputs": {"directories": [], "filenames": inputs},
                                "outputs": {"directories": [out_dir]}, "referencedPaths": []}}
