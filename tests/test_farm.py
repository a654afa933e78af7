# SPDX-License-Identifier: GPL-3.0-or-later
"""Issue 29: bakes on the job systems studios run. An Open Job Description bundle run task by
task with openjd-cli as a farm runs it (the good outputs equal a local batch's bit for bit,
a broken input fails only its own task and leaves no file, a second run changes no byte),
Verify, frame ranges in chunks, path mapping, a large bundle; the Flamenco job type
(under node, against a stub of Flamenco's job-authoring API) and the OpenCue command file
compile to the same commands as the OpenJD tasks; --skip-existing."""
from __future__ import annotations

import hashlib
import json
import os
import shlex
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from conftest import run_hao

from hao_addon.core.farm.manifest import make_manifest, read_manifest
from hao_addon.core.frame_ranges import format_frames, parse_frames

ROOT = Path(__file__).resolve().parent.parent
SPOT = ROOT / "samples" / "spot.obj"
CESIUM = ROOT / "tests" / "data" / "CesiumMan.glb"
OPENJD = Path(sys.executable).parent / "openjd"
BAKE = ["--size", "64", "--directions", "8", "--margin", "2"]


def hao(args, cwd: Path, **kw) -> subprocess.CompletedProcess:
    return run_hao(args, cwd=cwd, **kw)


def openjd(args, cwd: Path) -> subprocess.CompletedProcess:
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}  # the job sets its own
    return subprocess.run([str(OPENJD), *map(str, args)], capture_output=True, text=True, env=env, cwd=cwd,
                          timeout=600)


def run_task(bundle: Path, step: str, cwd: Path, *extra) -> subprocess.CompletedProcess:
    return openjd(["run", bundle / "template.json", "--job-param", f"file://{bundle / 'job_parameters.json'}",
                   "--step", step, *extra], cwd)


def maps(folder: Path) -> list[str]:
    """The files of an output folder, without the tasks' receipts (.hao-job)."""
    return sorted(n for n in os.listdir(folder) if n != ".hao-job")


def digests(folder: Path) -> dict[str, str]:
    return {p.name: hashlib.sha256(p.read_bytes()).hexdigest() for p in sorted(folder.iterdir()) if p.is_file()}


@pytest.fixture
def job_inputs(tmp_path) -> Path:
    """Four inputs, one broken, in two folders (the manifest keeps them relative)."""
    folder = tmp_path / "assets"
    (folder / "props").mkdir(parents=True)
    lines = SPOT.read_text().splitlines()
    for k, name in enumerate(("a", "b", "props/c")):  # scaled: no input is a cached re-bake of another
        scale = 1.0 + 0.01 * k
        (folder / f"{name}.obj").write_text("\n".join(
            "v " + " ".join(f"{float(x) * scale:.7g}" for x in line.split()[1:4]) if line.startswith("v ") else line
            for line in lines) + "\n")
    (folder / "broken.obj").write_text("this is not a mesh\n")
    return folder


def write_bundle(kind: str, inputs: list[Path], out: Path, bundle: Path, cwd: Path, *extra) -> None:
    done = hao(["farm", kind, *inputs, "--out-dir", out, "--bundle", bundle, "--runner", "python", "--executable",
                sys.executable, *extra], cwd)
    assert done.returncode == 0, done.stderr


def test_openjd_tasks_equal_a_local_batch_and_fail_only_for_their_own_inputs(job_inputs, tmp_path):
    files = [job_inputs / "a.obj", job_inputs / "broken.obj", job_inputs / "b.obj", job_inputs / "props" / "c.obj"]
    out, bundle, local = tmp_path / "out", tmp_path / "bundle", tmp_path / "local"
    out.mkdir()
    local.mkdir()
    write_bundle("openjd", files, out, bundle, tmp_path, "--chunk-size", "2", *BAKE)
    assert openjd(["check", bundle / "template.json"], tmp_path).returncode == 0
    manifest = read_manifest(bundle / "manifest.json")
    assert manifest.entries == ("a.obj", "broken.obj", "b.obj", "props/c.obj") and manifest.chunk_count == 2
    # As a farm runs them: each task alone (a local session stops at its first failed task).
    first, second = (run_task(bundle, "Bake", tmp_path, "-tp", f"Chunk={k}") for k in (0, 1))
    assert first.returncode != 0 and "broken.obj" in first.stdout and second.returncode == 0, second.stdout
    assert "openjd_progress: 100.0" in second.stdout
    assert sorted(n for n in os.listdir(out) if n != ".hao-job") == ["a_ao.png", "b_ao.png", "c_ao.png"]  # nothing of the broken one
    batch = hao(["bake", *[f for f in files if f.name != "broken.obj"], "--out-dir", local, *BAKE], tmp_path)
    assert batch.returncode == 0, batch.stderr
    assert digests(out) == digests(local)  # bit for bit what a workstation bakes
    # Re-run (a re-queued task): nothing baked again, no byte changed.
    before = {p: p.stat().st_mtime_ns for p in out.iterdir() if p.is_file()}
    again = run_task(bundle, "Bake", tmp_path, "-tp", "Chunk=1")
    assert again.returncode == 0 and "skipped 'b'" in again.stdout and "skipped 'c'" in again.stdout
    assert {p: p.stat().st_mtime_ns for p in out.iterdir() if p.is_file()} == before
    assert digests(out) == digests(local)
    # Verify: fails while the broken input has no map, naming it; and after a deletion.
    verify = run_task(bundle, "Verify", tmp_path, "--no-run-dependencies")
    assert verify.returncode != 0 and "1 of 4 expected outputs are missing, empty or broken: broken_ao.png" in verify.stdout


def test_verify_names_a_deleted_output_and_passes_when_all_exist(job_inputs, tmp_path):
    files = [job_inputs / "a.obj", job_inputs / "b.obj"]
    out, bundle = tmp_path / "out", tmp_path / "bundle"
    out.mkdir()
    write_bundle("openjd", files, out, bundle, tmp_path, "--chunk-size", "5", *BAKE)
    assert run_task(bundle, "Bake", tmp_path, "-tp", "Chunk=0").returncode == 0
    assert run_task(bundle, "Verify", tmp_path, "--no-run-dependencies").returncode == 0
    (out / "b_ao.png").unlink()
    verify = run_task(bundle, "Verify", tmp_path, "--no-run-dependencies")
    assert verify.returncode != 0 and "1 of 2 expected outputs are missing, empty or broken: b_ao.png" in verify.stdout


def test_a_frame_range_in_chunks_equals_the_single_process_sequence(tmp_path):
    out, bundle, local = tmp_path / "out", tmp_path / "bundle", tmp_path / "local"
    out.mkdir()
    local.mkdir()
    frames = "1-3,5,7-11:2"  # OpenJD's syntax, chunks that are not contiguous
    write_bundle("openjd", [CESIUM], out, bundle, tmp_path, "--frames", frames, "--chunk-size", "3", *BAKE)
    manifest = read_manifest(bundle / "manifest.json")
    assert [manifest.chunk_frames(k) for k in range(manifest.chunk_count)] == ["1-3", "5-9:2", "11"]
    for k in range(3):
        assert run_task(bundle, "Bake", tmp_path, "-tp", f"Chunk={k}").returncode == 0
    single = hao(["bake", CESIUM, "--frames", frames, "--out-dir", local, *BAKE], tmp_path)
    assert single.returncode == 0, single.stderr
    assert len(digests(out)) == 7 and digests(out) == digests(local)
    assert run_task(bundle, "Verify", tmp_path, "--no-run-dependencies").returncode == 0


def test_path_mapping_rewrites_the_roots(job_inputs, tmp_path):
    """The bundle names the roots as the submitter sees them; a worker's path-mapping rule
    (OpenJD's pathmapping-1.0) moves the input root elsewhere."""
    out, bundle = tmp_path / "out", tmp_path / "bundle"
    out.mkdir()
    write_bundle("openjd", [job_inputs / "a.obj"], out, bundle, tmp_path, *BAKE)
    moved = tmp_path / "worker_mount"
    shutil.move(str(job_inputs), moved)
    rules = {"version": "pathmapping-1.0", "path_mapping_rules": [
        {"source_path_format": "POSIX", "source_path": str(job_inputs), "destination_path": str(moved)}]}
    assert run_task(bundle, "Bake", tmp_path, "-tp", "Chunk=0").returncode != 0  # the old root is gone
    done = run_task(bundle, "Bake", tmp_path, "-tp", "Chunk=0", "--path-mapping-rules", json.dumps(rules))
    assert done.returncode == 0, done.stdout
    assert maps(out) == ["a_ao.png"]


def test_every_bake_option_reaches_each_task_unchanged(tmp_path):
    high = tmp_path / "high.obj"
    high.write_bytes(SPOT.read_bytes())
    options = ["--size", "96", "--directions", "24", "--max-distance", "0.5", "--falloff", "wendland", "--margin",
               "3", "--occluders", "target", "--uv-map", "UVMap", "--object", "spot", "--high-poly", str(high),
               "--cage-extrusion", "0.01", "--bent-space", "object", "--ignore-back-faces", "--seed", "7"]
    write_bundle("openjd", [SPOT], tmp_path / "out", tmp_path / "b", tmp_path, *options)
    template = json.loads((tmp_path / "b" / "template.json").read_text())
    args = template["steps"][0]["script"]["actions"]["onRun"]["args"]
    assert args[:args.index("--skip-existing")] == ["-m", "hao_addon", "bake", "--manifest={{Param.Manifest}}",
                                                    "--chunk={{Task.Param.Chunk}}", "--input-root={{Param.InputRoot}}",
                                                    "--out-dir={{Param.OutputDir}}"]
    forwarded = args[args.index("--progress=openjd") + 2:]  # after the receipt (--json)
    from hao_addon.cli.parser import build_parser
    parse = build_parser().parse_args
    given = vars(parse(["bake", str(SPOT), *options]))
    task = vars(parse(["bake", str(SPOT), *forwarded]))
    assert task == given and len(forwarded) == 13  # each of the 13 options once ('--name=value' or a flag)
    assert "hao 0.1.0" in template["description"]


def flamenco_tasks(script: Path, settings: dict) -> list[dict]:
    """compileJob of a job type under node, against a stub of Flamenco's authoring API."""
    stub = """
const vm = require("vm"), fs = require("fs");
const tasks = [];
const author = {
  Task: (name, type) => ({ name, type, commands: [], deps: [],
                           addCommand(c) { this.commands.push(c); }, addDependency(t) { this.deps.push(t.name); } }),
  Command: (type, params) => ({ type, params }),
};
const job = { settings: JSON.parse(process.argv[2]), addTask: (t) => tasks.push(t) };
const context = { author, print: () => {} };
vm.createContext(context);
vm.runInContext(fs.readFileSync(process.argv[1], "utf8") + "\\ncompileJob(job);", Object.assign(context, { job }));
console.log(JSON.stringify(tasks.map((t) => ({ name: t.name, deps: t.deps, commands: t.commands }))));
"""
    done = subprocess.run(["node", "-e", stub, str(script), json.dumps(settings)], capture_output=True, text=True,
                          timeout=60)
    assert done.returncode == 0, done.stderr
    return json.loads(done.stdout)


def openjd_commands(bundle: Path) -> list[list[str]]:
    """The concrete commands of the OpenJD bundle's tasks (its parameters substituted)."""
    template = json.loads((bundle / "template.json").read_text())
    params = json.loads((bundle / "job_parameters.json").read_text())
    chunks = read_manifest(bundle / "manifest.json").chunk_count

    def concrete(action: dict, chunk: str) -> list[str]:
        words = [action["command"], *action["args"]]
        for name, value in params.items():
            words = [w.replace(f"{{{{Param.{name}}}}}", value) for w in words]
        return [w.replace("{{Task.Param.Chunk}}", chunk) for w in words]
    bake, verify = (step["script"]["actions"]["onRun"] for step in template["steps"])
    env = ["env", f"PYTHONPATH={params['AddonPath']}"]
    return [env + concrete(bake, str(k)) for k in range(chunks)] + [env + concrete(verify, "")]


def test_flamenco_and_opencue_compile_to_the_openjd_tasks_commands(job_inputs, tmp_path):
    files = [job_inputs / "a.obj", job_inputs / "b.obj", job_inputs / "props" / "c.obj"]
    out = tmp_path / "out"
    bundle = tmp_path / "job"  # the three formats side by side, over one manifest
    for kind in ("openjd", "flamenco", "opencue"):
        write_bundle(kind, files, out, bundle, tmp_path, "--chunk-size", "2", *BAKE)
    expected = openjd_commands(bundle)
    job = json.loads((bundle / "job.json").read_text())
    tasks = flamenco_tasks(bundle / "hao_bake.js", job["settings"])
    assert [t["name"] for t in tasks] == ["bake-0", "bake-1", "verify"]
    assert tasks[-1]["deps"] == ["bake-0", "bake-1"]
    compiled = [[c["params"]["exe"], *c["params"]["args"]] for t in tasks for c in t["commands"]]
    assert all(c["type"] == "exec" for t in tasks for c in t["commands"])
    assert compiled == expected
    lines = (bundle / "hao_commands.txt").read_text().splitlines()
    assert [shlex.split(line) for line in lines] == expected


def test_an_opencue_line_runs_as_written(job_inputs, tmp_path):
    out = tmp_path / "out"
    out.mkdir()
    write_bundle("opencue", [job_inputs / "a.obj"], out, tmp_path / "cue", tmp_path, *BAKE)
    first = (tmp_path / "cue" / "hao_commands.txt").read_text().splitlines()[0]
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    done = subprocess.run(first, shell=True, capture_output=True, text=True, env=env, cwd=tmp_path, timeout=300)
    assert done.returncode == 0, done.stderr
    assert maps(out) == ["a_ao.png"]


def test_a_bundle_of_1500_inputs_is_valid(tmp_path):
    """More than OpenJD's 1,024 list values: the chunk is an INT range, the inputs are in the
    manifest. No mesh is loaded (and no Blender)."""
    folder = tmp_path / "many"
    folder.mkdir()
    for k in range(1500):
        (folder / f"m{k:04d}.obj").write_bytes(b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
    done = hao(["farm", "openjd", *sorted(folder.iterdir()), "--out-dir", tmp_path, "--bundle", tmp_path / "b",
                "--chunk-size", "1", "--json", "-"], tmp_path)
    assert done.returncode == 0, done.stderr
    report = json.loads(done.stdout)
    assert report["settings"]["tasks"] == 1500 and report["blender"] == ""  # Blender was not loaded
    assert openjd(["check", tmp_path / "b" / "template.json"], tmp_path).returncode == 0
    assets = json.loads((tmp_path / "b" / "asset_references.json").read_text())["assetReferences"]
    assert len(assets["inputs"]["filenames"]) == 1501 and assets["outputs"]["directories"] == [str(tmp_path)]


# -- --skip-existing and the manifest's pieces ------------------------------------------------------

def test_skip_existing_rebakes_what_changed_and_keeps_what_is_current(tmp_path):
    source = tmp_path / "s.obj"
    source.write_bytes(SPOT.read_bytes())
    out = tmp_path / "s.png"
    assert hao(["bake", source, "--out", out, *BAKE, "--quiet"], tmp_path).returncode == 0
    first = out.read_bytes()
    kept = hao(["bake", source, "--out", out, *BAKE, "--skip-existing", "--json", "-"], tmp_path)
    report = json.loads(kept.stdout)
    assert report["skipped"] == [str(out)] and report["outputs"] == [str(out)] and out.read_bytes() == first
    for changed in (["--size", "32"], ["--seed", "3"]):  # other settings: baked again
        args = [*BAKE, *changed]
        redone = json.loads(hao(["bake", source, "--out", out, *args, "--skip-existing", "--json", "-"],
                                tmp_path).stdout)
        assert "skipped" not in redone and out.read_bytes() != first
        assert hao(["bake", source, "--out", out, *BAKE, "--quiet"], tmp_path).returncode == 0
    source.write_text(SPOT.read_text().replace("v 0.", "v 0.0", 1))  # other input contents: baked again
    redone = json.loads(hao(["bake", source, "--out", out, *BAKE, "--skip-existing", "--json", "-"], tmp_path).stdout)
    assert "skipped" not in redone
    out.write_bytes(first[:100])  # a file cut short (not ours, no key): baked again
    redone = json.loads(hao(["bake", source, "--out", out, *BAKE, "--skip-existing", "--json", "-"], tmp_path).stdout)
    assert "skipped" not in redone and out.read_bytes().startswith(b"\x89PNG") and len(out.read_bytes()) > 100


def test_frame_ranges_in_openjd_syntax():
    assert parse_frames("1-3,5,7-11:2") == [1, 2, 3, 5, 7, 9, 11]
    assert parse_frames("-3--1") == [-3, -2, -1]
    for frames in ([1, 2, 3, 5, 7, 9, 11], [4], [1, 3], [10, 20, 30, 31], [-2, -1, 0, 1]):
        assert parse_frames(format_frames(frames)) == frames
    assert format_frames([1, 2, 3, 5, 7, 9, 11]) == "1-3,5-11:2"
    for bad, message in (("1-3,2", "names a frame twice"), ("1-5000,5001-10002", "more than 10000"),
                         ("1-", "expected A-B")):
        with pytest.raises(ValueError, match=message):
            parse_frames(bad)


def test_a_manifest_holds_its_inputs_relative_to_their_common_folder(tmp_path):
    paths = [str(tmp_path / "x" / "a.obj"), str(tmp_path / "x" / "y" / "b.obj"), str(tmp_path / "x" / "c.obj")]
    manifest = make_manifest(paths, 2, "{input}_ao.png")
    assert manifest.root == str(tmp_path / "x") and manifest.entries == ("a.obj", "y/b.obj", "c.obj")
    assert [manifest.chunk_inputs(k) for k in range(manifest.chunk_count)] == [["a.obj", "y/b.obj"], ["c.obj"]]
    with pytest.raises(ValueError, match="chunk 2 is not in this job"):
        manifest.chunk_inputs(2)
    with pytest.raises(ValueError, match="one input"):
        make_manifest(paths, 2, "{input}_ao.png", frames="1-4")


def test_a_task_killed_at_any_moment_reruns_to_the_same_bytes(job_inputs, tmp_path):
    """SIGKILL (no handler runs) at several moments of a task, then the task again: every
    output exists and equals the uninterrupted run's; no visible file is ever half-written
    (a killed write leaves at most a hidden '.hao-*.part')."""
    import signal
    import time

    files = [job_inputs / "a.obj", job_inputs / "b.obj", job_inputs / "props" / "c.obj"]
    settings = ["--size", "128", "--directions", "32", "--margin", "2"]
    whole = tmp_path / "whole"
    write_bundle("openjd", files, whole, tmp_path / "bundle", tmp_path, "--chunk-size", "3", *settings)
    task = openjd_commands(tmp_path / "bundle")[0]
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    whole.mkdir()
    assert subprocess.run(task, capture_output=True, env=env, cwd=tmp_path, timeout=300).returncode == 0
    expected = digests(whole)
    killed = tmp_path / "killed"
    killed.mkdir()
    cut = [w.replace(str(whole), str(killed)) for w in task]
    for delay in (0.3, 1.0, 1.6, 2.2, 2.8):
        proc = subprocess.Popen(cut, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, env=env, cwd=tmp_path)
        time.sleep(delay)
        proc.send_signal(signal.SIGKILL)
        proc.wait(timeout=60)
        for path in killed.iterdir():
            if not path.name.startswith("."):  # every visible file is complete: one of the expected ones
                assert hashlib.sha256(path.read_bytes()).hexdigest() == expected[path.name], (delay, path.name)
    assert subprocess.run(cut, capture_output=True, env=env, cwd=tmp_path, timeout=300).returncode == 0
    assert {k: v for k, v in digests(killed).items() if not k.startswith(".")} == expected


BLENDER_COMMAND = r'''
import importlib.util, json, os, sys
import bpy
root, args = sys.argv[1], json.loads(sys.argv[2])
registered = {}
bpy.utils.register_cli_command = lambda name, fn: registered.setdefault(name, fn)  # what Blender keeps
spec = importlib.util.spec_from_file_location("hao_ext", os.path.join(root, "__init__.py"),
                                              submodule_search_locations=[root])
module = importlib.util.module_from_spec(spec)
sys.modules["hao_ext"] = module
spec.loader.exec_module(module)
module.register()
assert args[:3] == ["-b", "-c", "hao"], args  # blender -b -c hao <the command's arguments>
code = registered[args[2]](args[3:])
sys.stdout.flush()
os._exit(code)
'''


def test_the_blender_runner_calls_the_extensions_command_with_the_same_bake(job_inputs, tmp_path):
    """--runner blender: 'blender -b -c hao bake ...'. No Blender binary here: the task's
    arguments after the executable go to the command the installed extension registers
    (operators/cli_command.py), as Blender passes them, and bake what the python runner bakes."""
    out = tmp_path / "out"
    out.mkdir()
    done = hao(["farm", "openjd", job_inputs / "a.obj", "--out-dir", out, "--bundle", tmp_path / "job", *BAKE],
               tmp_path)
    assert done.returncode == 0, done.stderr
    template = json.loads((tmp_path / "job" / "template.json").read_text())
    assert [p["name"] for p in template["parameterDefinitions"]] == ["InputRoot", "OutputDir", "Manifest",
                                                                   "Executable"]
    params = json.loads((tmp_path / "job" / "job_parameters.json").read_text())
    assert params["Executable"] == "blender"
    args = [a.replace("{{Param.Manifest}}", params["Manifest"]).replace("{{Param.InputRoot}}", params["InputRoot"])
            .replace("{{Param.OutputDir}}", params["OutputDir"]).replace("{{Task.Param.Chunk}}", "0")
            for a in template["steps"][0]["script"]["actions"]["onRun"]["args"]]
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    run = subprocess.run([sys.executable, "-c", BLENDER_COMMAND, str(ROOT), json.dumps(args)], capture_output=True,
                         text=True, env=env, cwd=tmp_path, timeout=300)
    assert run.returncode == 0, run.stderr
    assert maps(out) == ["a_ao.png"] and "openjd_progress: 100.0" in run.stdout
    local = hao(["bake", job_inputs / "a.obj", "--out", tmp_path / "a_ao.png", *BAKE], tmp_path)
    assert local.returncode == 0 and (tmp_path / "a_ao.png").read_bytes() == (out / "a_ao.png").read_bytes()


# -- issue 38: hostile names, collisions, every output checked ------------------------------------

# One folder name holding what shells, OpenJD's and Flamenco's parsers treat specially: a
# command substitution, backticks, ';' and '&', both quotes, a leading '-', unicode, OpenJD's
# '{{ }}' and a Flamenco placeholder. A newline is refused (below).
HOSTILE = "-x $(touch PWNED1) `touch PWNED2` ; touch PWNED3 & 'q' \"d\" ünï 漢 {{Param.OutputDir}} {chunk}"


def _hostile_job(tmp_path: Path, kind: str) -> tuple[Path, Path, Path]:
    folder = tmp_path / "in" / HOSTILE
    folder.mkdir(parents=True)
    (folder / "a.obj").write_bytes(SPOT.read_bytes())
    out, bundle = tmp_path / ("out " + HOSTILE), tmp_path / "job"
    write_bundle(kind, [folder / "a.obj"], out, bundle, tmp_path, *BAKE, "--thickness-out",
                 "{input}_thick {x}.png")
    return folder, out, bundle


def _nothing_ran(tmp_path: Path) -> None:
    assert not [p for p in tmp_path.rglob("PWNED*")] and not list(Path.cwd().glob("PWNED*"))


def _job_done(out: Path) -> None:
    assert maps(out) == ["a_ao.png", "a_thick {x}.png"]


def test_hostile_names_run_as_data_under_openjd(tmp_path):
    _folder, out, bundle = _hostile_job(tmp_path, "openjd")
    assert openjd(["check", bundle / "template.json"], tmp_path).returncode == 0
    bake = run_task(bundle, "Bake", tmp_path, "-tp", "Chunk=0")
    assert bake.returncode == 0, bake.stdout[-2000:]
    assert run_task(bundle, "Verify", tmp_path, "--no-run-dependencies").returncode == 0
    _job_done(out)
    _nothing_ran(tmp_path)


def test_hostile_names_run_as_data_in_opencue_lines_through_a_shell(tmp_path):
    _folder, out, bundle = _hostile_job(tmp_path, "opencue")
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    lines = (bundle / "hao_commands.txt").read_text().splitlines()
    assert len(lines) == 2  # a bake and the verify: nothing split a line
    for line in lines:
        done = subprocess.run(line, shell=True, capture_output=True, text=True, env=env, cwd=tmp_path, timeout=300)
        assert done.returncode == 0, done.stderr[-2000:]
    _job_done(out)
    _nothing_ran(tmp_path)


def test_hostile_names_run_as_data_in_the_flamenco_job_type(tmp_path):
    folder, out, bundle = _hostile_job(tmp_path, "flamenco")
    settings = json.loads((bundle / "job.json").read_text())["settings"]
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    for task in flamenco_tasks(bundle / "hao_bake.js", settings):
        for command in task["commands"]:  # Flamenco's exec: the program and its arguments, no shell
            args = [command["params"]["exe"], *command["params"]["args"]]
            assert f"--input-root={folder}" in args or task["name"] == "verify"
            done = subprocess.run(args, capture_output=True, text=True, env=env, cwd=tmp_path, timeout=300)
            assert done.returncode == 0, done.stderr[-2000:]
    _job_done(out)
    _nothing_ran(tmp_path)


@pytest.mark.parametrize("kind", ["openjd", "flamenco", "opencue"])
def test_a_newline_in_a_path_is_refused_by_every_format(tmp_path, kind):
    folder = tmp_path / "in\ntouch PWNED"
    folder.mkdir()
    (folder / "a.obj").write_bytes(SPOT.read_bytes())
    done = hao(["farm", kind, folder / "a.obj", "--out-dir", tmp_path / "out", "--bundle", tmp_path / "job"],
               tmp_path)
    assert done.returncode == 2 and "contains a control character (a newline)" in done.stderr
    assert not (tmp_path / "job").exists() and not (tmp_path / "out").exists()


def test_verify_wants_every_map_of_every_input_whole(job_inputs, tmp_path):
    """Every --maps kind and extra output, by its exact name; a truncated map or a folder in
    a map's place fails; an {object} name of one input never stands for another's."""
    files = [job_inputs / "a.obj", job_inputs / "b.obj"]
    out, bundle = tmp_path / "out", tmp_path / "bundle"
    write_bundle("openjd", files, out, bundle, tmp_path, "--chunk-size", "5", "--maps", "ao,thickness,error",
                 "--out", "{input}_{object}.png", "--gltf-out", "{input}.glb", *BAKE)
    assert run_task(bundle, "Bake", tmp_path, "-tp", "Chunk=0").returncode == 0
    expected = ["a.glb", "a_a.png", "a_a_error.png", "a_a_thickness.png",  # {object}: the OBJ's mesh 'a'
                "b.glb", "b_b.png", "b_b_error.png", "b_b_thickness.png"]
    assert maps(out) == expected
    assert run_task(bundle, "Verify", tmp_path, "--no-run-dependencies").returncode == 0
    thickness = out / "b_b_thickness.png"
    whole = thickness.read_bytes()
    for damage in ("cut", "folder", "deleted"):
        if thickness.is_file():
            thickness.unlink()
        if damage == "cut":
            thickness.write_bytes(whole[:len(whole) // 2])
        elif damage == "folder":
            thickness.mkdir()
        verify = run_task(bundle, "Verify", tmp_path, "--no-run-dependencies")
        assert verify.returncode != 0 and "1 of 8 expected outputs are missing, empty or broken: " \
            "b_{object}_thickness.png" in verify.stdout, (damage, verify.stdout[-1500:])
        if damage == "folder":
            thickness.rmdir()
    thickness.write_bytes(whole)
    (out / "a.glb").write_bytes((out / "a.glb").read_bytes()[:100])
    verify = run_task(bundle, "Verify", tmp_path, "--no-run-dependencies")
    assert verify.returncode != 0 and "expected outputs are missing, empty or broken: a.glb" in verify.stdout


def test_a_truncated_map_is_baked_again_by_skip_existing(tmp_path):
    """Its key sits in the header that survives the cut: the file must decode in full."""
    out = tmp_path / "a.png"
    args = ["bake", SPOT, "--out", out, "--skip-existing", *BAKE]
    assert hao(args, tmp_path).returncode == 0
    whole = out.read_bytes()
    out.write_bytes(whole[:len(whole) - 20])
    again = hao(args, tmp_path)
    assert again.returncode == 0 and "skipped" not in again.stdout and out.read_bytes() == whole


def test_a_killed_tasks_temporary_files_are_removed_by_its_next_run(tmp_path):
    from hao_addon.core.imageio import temporary_prefix
    out = tmp_path / "out"
    out.mkdir()
    stale = out / f"{temporary_prefix(out / 'spot_ao.png')}abc123.part"
    stale.write_bytes(b"half a map")
    other = out / ".hao-00000000-zzz.part"  # another file's: not this task's to remove
    other.write_bytes(b"x")
    assert hao(["bake", SPOT, "--out-dir", out, *BAKE], tmp_path).returncode == 0
    assert not stale.exists() and other.exists()


def _changed_value(field, spec):
    """A valid value of a setting other than its default (from its own definition)."""
    default = field.default
    if spec.choices:
        return next(c.value for c in spec.choices if c.value != default)
    if isinstance(default, bool):
        return not default
    if isinstance(default, str):
        return default + "_x"
    step = 1 if isinstance(default, int) else 0.25
    value = default + step
    if spec.maximum is not None and value > spec.maximum:
        value = default - step
    return value


def test_the_skip_key_covers_every_setting_from_its_definition():
    """Each BakeSettings and JobOptions setting with an option, changed alone from its
    default, changes the key: a setting dropped from it (directions, say) fails here."""
    import argparse

    from hao_addon.cli.parser import build_parser
    from hao_addon.cli.skip import NOT_IN_KEY, run_key
    from hao_addon.core.bake.job_options import JobOptions
    from hao_addon.core.bake.settings import BakeSettings
    from hao_addon.core.setting_spec import specs
    base = build_parser().parse_args(["bake", str(SPOT), "--out", "a.png"])
    key = run_key(base, [SPOT])
    checked = []
    for cls in (BakeSettings, JobOptions):
        for field, spec in specs(cls):
            option = spec.option(field.name)
            if option is None:
                continue
            dest = option[2:].replace("-", "_")
            assert dest not in NOT_IN_KEY, dest
            args = argparse.Namespace(**vars(base))
            assert hasattr(args, dest), dest
            setattr(args, dest, _changed_value(field, spec))
            assert run_key(args, [SPOT]) != key, f"{option} does not change the skip key"
            checked.append(dest)
    assert "directions" in checked and "max_distance" in checked and len(checked) >= 30, checked
    # The input's content counts too.
    assert run_key(base, [CESIUM]) != key


ALPHA_SCENE = r'''
import os, sys
import bpy
import numpy as np
folder = sys.argv[-1]
bpy.ops.wm.read_factory_settings(use_empty=True)
image = bpy.data.images.new("mask", 8, 8, alpha=True)
image.pixels.foreach_set(np.tile([1.0, 1.0, 1.0, 0.5], 64).astype(np.float32))
image.filepath_raw, image.file_format = os.path.join(folder, "mask.png"), 'PNG'
image.save()
bpy.ops.mesh.primitive_plane_add(size=4)
bpy.context.active_object.name = "Floor"
bpy.ops.mesh.primitive_plane_add(size=4, location=(0, 0, 0.5))
card = bpy.context.active_object
card.name = "Card"
material = bpy.data.materials.new("CardMaterial")
material.use_nodes = True
nodes = material.node_tree.nodes
texture = nodes.new('ShaderNodeTexImage')
texture.image = image
material.node_tree.links.new(texture.outputs['Alpha'], nodes["Principled BSDF"].inputs['Alpha'])
card.data.materials.append(material)
bpy.ops.wm.save_as_mainfile(filepath=os.path.join(folder, "scene.blend"))
'''


@pytest.fixture
def alpha_scene(tmp_path) -> Path:
    folder = tmp_path / "scene"
    folder.mkdir()
    done = subprocess.run([sys.executable, "-c", ALPHA_SCENE, str(folder)], capture_output=True, text=True,
                          timeout=300)
    assert done.returncode == 0, done.stderr[-2000:]
    return folder


def test_the_scenes_textures_are_inputs(alpha_scene, tmp_path):
    """An alpha texture edited on disk makes the map stale; a map onto a texture the scene's
    materials read is refused, the texture untouched."""
    out = tmp_path / "floor.png"
    args = ["bake", alpha_scene / "scene.blend", "--object", "Floor", "--out", out, "--skip-existing", *BAKE]
    assert hao(args, tmp_path).returncode == 0
    again = hao(args, tmp_path)
    assert again.returncode == 0 and "skipped 'Floor'" in again.stdout
    mask = alpha_scene / "mask.png"
    before = mask.read_bytes()
    for option in ("--out", "--orm-out"):
        onto = hao(["bake", alpha_scene / "scene.blend", "--object", "Floor", *(["--out", out] if option != "--out"
                    else []), option, mask, *BAKE], tmp_path)
        assert onto.returncode == 2 and "would overwrite the image 'mask' that the scene's materials read" \
            in onto.stderr, onto.stderr
        assert mask.read_bytes() == before
    # Edit the texture (another alpha): the map is baked again.
    import bpy
    image = bpy.data.images.load(str(mask))
    image.pixels.foreach_set(np.tile([1.0, 1.0, 1.0, 0.9], 64).astype(np.float32))
    image.save()
    bpy.data.images.remove(image)
    assert mask.read_bytes() != before
    third = hao(args, tmp_path)
    assert third.returncode == 0 and "skipped" not in third.stdout, third.stdout


def test_verify_wants_every_frame_and_every_udim_tile(tmp_path):
    """A frame's map deleted fails Verify naming that frame's file; a map on UDIM tiles is
    checked tile by tile as its task recorded them; a stray tile never stands for a map."""
    from test_cli_runs import write_obj
    from test_udim import TILES, combined, islands
    out, bundle = tmp_path / "out", tmp_path / "bundle"
    write_bundle("openjd", [CESIUM], out, bundle, tmp_path, "--frames", "1-3", "--chunk-size", "3", *BAKE)
    assert run_task(bundle, "Bake", tmp_path, "-tp", "Chunk=0").returncode == 0
    assert run_task(bundle, "Verify", tmp_path, "--no-run-dependencies").returncode == 0
    (out / "CesiumMan_ao_0002.png").unlink()
    verify = run_task(bundle, "Verify", tmp_path, "--no-run-dependencies")
    assert verify.returncode != 0 and "1 of 3 expected outputs are missing, empty or broken: CesiumMan_ao_0002.png" \
        in verify.stdout
    # UDIM tiles: each one the task wrote must be there and whole.
    source = tmp_path / "udim" / "tiles.obj"
    source.parent.mkdir()
    write_obj(source, {"udim": combined(islands(), TILES)})
    out, bundle = tmp_path / "out_udim", tmp_path / "bundle_udim"
    write_bundle("openjd", [source], out, bundle, tmp_path, "--out", "{input}.<UDIM>.png", *BAKE)
    assert run_task(bundle, "Bake", tmp_path, "-tp", "Chunk=0").returncode == 0
    assert maps(out) == [f"tiles.{tile}.png" for tile in TILES]
    assert run_task(bundle, "Verify", tmp_path, "--no-run-dependencies").returncode == 0
    (out / f"tiles.{TILES[1]}.png").write_bytes(b"")
    verify = run_task(bundle, "Verify", tmp_path, "--no-run-dependencies")
    assert verify.returncode != 0 and "1 of 1 expected outputs are missing, empty or broken: tiles.<UDIM>.png" \
        in verify.stdout


def test_a_stray_tile_never_stands_for_a_map(job_inputs, tmp_path):
    files = [job_inputs / "a.obj"]
    out, bundle = tmp_path / "out", tmp_path / "bundle"
    write_bundle("openjd", files, out, bundle, tmp_path, *BAKE)
    assert run_task(bundle, "Bake", tmp_path, "-tp", "Chunk=0").returncode == 0
    (out / "a_ao.png").rename(out / "a_ao.1001.png")
    verify = run_task(bundle, "Verify", tmp_path, "--no-run-dependencies")
    assert verify.returncode != 0 and "1 of 1 expected outputs are missing, empty or broken: a_ao.png" in verify.stdout
    shutil.rmtree(out / ".hao-job")  # without the task's receipt: the exact name only
    verify = run_task(bundle, "Verify", tmp_path, "--no-run-dependencies")
    assert verify.returncode != 0 and "a_ao.png" in verify.stdout


def test_every_output_kind_of_a_farm_task_lands_in_the_out_dir(job_inputs, tmp_path):
    """Relative extra outputs are names in --out-dir: before, they went to the session's
    scratch folder, which openjd deletes, and the job still passed."""
    out, bundle, cwd = tmp_path / "out", tmp_path / "bundle", tmp_path / "elsewhere"
    cwd.mkdir()
    write_bundle("openjd", [job_inputs / "a.obj"], out, bundle, cwd, "--bent-normal-out", "{input}_bent.png",
                 "--thickness-out", "{input}_thick.exr", "--orm-out", "{input}_orm.png", "--error-out",
                 "{input}_err.exr", "--gltf-out", "{input}.glb", *BAKE)
    manifest = read_manifest(bundle / "manifest.json")
    assert manifest.outputs == ("{input}_ao.png", "{input}_bent.png", "{input}_thick.exr", "{input}_orm.png",
                                "{input}_err.exr", "{input}.glb")
    assert run_task(bundle, "Bake", cwd, "-tp", "Chunk=0").returncode == 0
    assert maps(out) == ["a.glb", "a_ao.png", "a_bent.png", "a_err.exr", "a_orm.png", "a_thick.exr"]
    assert list(cwd.iterdir()) == []
    assert run_task(bundle, "Verify", cwd, "--no-run-dependencies").returncode == 0


def test_a_failed_task_leaves_no_folder_behind(job_inputs, tmp_path):
    out, bundle = tmp_path / "not" / "yet", tmp_path / "bundle"
    write_bundle("openjd", [job_inputs / "broken.obj"], out, bundle, tmp_path, *BAKE)
    assert run_task(bundle, "Bake", tmp_path, "-tp", "Chunk=0").returncode != 0
    assert not (tmp_path / "not").exists()


def test_file_names_are_cleaned_as_blender_cleans_them_without_loading_it():
    """{input} names come from core.output_files.clean_name (a farm writer loads no Blender),
    Blender's bpy.path.clean_name character for character."""
    import bpy

    from hao_addon.core.output_files import clean_name
    names = ["spot", "a b", "a_b", "x-y.z", "ünï 漢 ÿ", "$(touch x) `y` ; & 'q' \"d\"", "".join(map(chr, range(300)))]
    for name in names:
        assert clean_name(name) == bpy.path.clean_name(name), name
