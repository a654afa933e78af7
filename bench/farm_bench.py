# SPDX-License-Identifier: GPL-3.0-or-later
"""Farm benchmark (issue 29): what running bakes as Open Job Description tasks costs against
one local batch, in one run on one machine.

    .venv/bin/python bench/farm_bench.py [--inputs 50] [--out bench/results]

Rows, timed end to end (process start, Blender, GPU context, shaders included); the first
three interleaved, REPEATS times each, the median kept (the machine is shared):
- local batch: `bake` of N inputs in one process (--out-dir);
- the task's command: the same N inputs as one chunk, the command an OpenJD task runs
  (bake --manifest --chunk --skip-existing --progress openjd), started directly;
- one farm task: that chunk run by `openjd run --step Bake` as a farm worker runs a task, timed
  two ways: the OpenJD session (the "Duration" openjd reports: environment, action, progress
  lines, clean-up; what a resident worker agent spends on the task, the issue's target of at
  most 1.1x the local batch) and the whole `openjd run` process (adds openjd-cli's own Python
  start-up, about 0.6 s, which a worker agent pays once, not per task);
- one task per input: N chunks of 1, each its own `openjd run`, once, their sessions summed
  (what a chunk saves);
- writing the bundle of 10,000 inputs (`farm openjd`, which loads no Blender; target 5 s).
The inputs are Spot scaled by 1 + k/1000 (no input is a cached re-bake of another), baked at
256^2 with 64 directions. Writes farm_bench.json and farm_bench.png into the output folder.
"""
from __future__ import annotations

import argparse
import json
import os
import platform
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
SPOT = ROOT / "samples" / "spot.obj"
OPENJD = Path(sys.executable).parent / "openjd"
BAKE = ["--size", "256", "--directions", "64", "--margin", "4"]
BUNDLE_INPUTS = 10_000
REPEATS = 5


def run(args: list, cwd: Path) -> float:
    """Seconds of one command, which must succeed."""
    return run_with_output(args, cwd)[0]


def run_with_output(args: list, cwd: Path) -> tuple[float, str]:
    """Seconds and standard output of one command, which must succeed."""
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    t0 = time.perf_counter()
    done = subprocess.run([str(a) for a in args], capture_output=True, text=True, env=env, cwd=cwd)
    seconds = time.perf_counter() - t0
    if done.returncode != 0:
        raise SystemExit(f"{args[:4]} failed: {done.stderr[-2000:]}{done.stdout[-2000:]}")
    return seconds, done.stdout


def session_seconds(openjd_output: str) -> float:
    """The session's duration as `openjd run` reports it ("Duration: S seconds")."""
    line = next(line for line in openjd_output.splitlines() if line.startswith("Duration:"))
    return float(line.split()[1])


def write_inputs(folder: Path, count: int) -> list[Path]:
    lines = SPOT.read_text().splitlines()
    paths = []
    for k in range(count):
        scale = 1.0 + k / 1000.0
        path = folder / f"spot{k:03d}.obj"
        path.write_text("\n".join("v " + " ".join(f"{float(x) * scale:.7g}" for x in line.split()[1:4])
                                  if line.startswith("v ") else line for line in lines) + "\n")
        paths.append(path)
    return paths


def hao(*args) -> list:
    return [sys.executable, "-m", "hao_addon", *args]


def task_runs(bundle: Path, chunks: int, cwd: Path, out: Path | None = None) -> tuple[float, float]:
    """Seconds of every Bake task of a bundle, each its own `openjd run` (as a farm runs them),
    into the bundle's output folder or out: (the processes' wall time, the sessions' durations)."""
    values = json.loads((bundle / "job_parameters.json").read_text())
    if out is not None:
        values["OutputDir"] = str(out)
    (cwd / "params.json").write_text(json.dumps(values))
    wall = session = 0.0
    for k in range(chunks):
        seconds, output = run_with_output([OPENJD, "run", bundle / "template.json", "--job-param",
                                           f"file://{cwd / 'params.json'}", "--step", "Bake", "-tp", f"Chunk={k}"], cwd)
        wall, session = wall + seconds, session + session_seconds(output)
    return wall, session


def task_command(bundle: Path) -> list[str]:
    """The first Bake task's command, its parameters filled in ('{out}' for the output folder)."""
    template = json.loads((bundle / "template.json").read_text())
    values = json.loads((bundle / "job_parameters.json").read_text())
    action = template["steps"][0]["script"]["actions"]["onRun"]
    words = [action["command"], *action["args"]]
    for name, value in {**values, "OutputDir": "{out}"}.items():
        words = [w.replace(f"{{{{Param.{name}}}}}", value) for w in words]
    return [w.replace("{{Task.Param.Chunk}}", "0") for w in words]


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--inputs", type=int, default=50)
    ap.add_argument("--out", default=str(ROOT / "bench" / "results"))
    opts = ap.parse_args()
    out = Path(opts.out)
    out.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory() as scratch:
        tmp = Path(scratch)
        (tmp / "in").mkdir()
        inputs = write_inputs(tmp / "in", opts.inputs)
        farm = ["--runner", "python", "--executable", sys.executable, *BAKE]
        run(hao("farm", "openjd", *inputs, "--out-dir", tmp / "outputs", "--bundle", tmp / "one",
                "--chunk-size", opts.inputs, *farm), tmp)
        command = task_command(tmp / "one")
        times = {"local batch": [], "the task's command": [], "one farm task": [], "one farm task (openjd run)": []}
        for k in range(REPEATS):  # interleaved, each into an empty folder
            folders = {name: tmp / f"{name.replace(' ', '_')}{k}" for name in list(times)[:3]}
            for folder in folders.values():
                folder.mkdir()
            times["local batch"].append(run(hao("bake", *inputs, "--out-dir", folders["local batch"], *BAKE,
                                                "--quiet"), tmp))
            times["the task's command"].append(run([a.replace("{out}", str(folders["the task's command"]))
                                                    for a in command], tmp))
            wall, session = task_runs(tmp / "one", 1, tmp, folders["one farm task"])
            times["one farm task"].append(session)
            times["one farm task (openjd run)"].append(wall)
        rows = {name: statistics.median(values) for name, values in times.items()}
        run(hao("farm", "openjd", *inputs, "--out-dir", tmp / "each_out", "--bundle", tmp / "each",
                "--chunk-size", "1", *farm), tmp)
        each_wall, rows["one task per input"] = task_runs(tmp / "each", opts.inputs, tmp)
        local, task = (tmp / "local_batch0"), (tmp / "one_farm_task0")
        same = all((task / p.name).read_bytes() == p.read_bytes() for p in local.iterdir())
        (tmp / "many").mkdir()
        for k in range(BUNDLE_INPUTS):
            (tmp / "many" / f"m{k:05d}.obj").write_bytes(b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
        many = sorted((tmp / "many").iterdir())
        bundle_seconds = run(hao("farm", "openjd", *many, "--out-dir", tmp / "o", "--bundle", tmp / "big",
                                 "--chunk-size", "10"), tmp)
    result = {
        "machine": {"platform": platform.platform(), "cpus": os.cpu_count(), "python": sys.version.split()[0]},
        "inputs": opts.inputs, "bake_options": BAKE, "seconds": {k: round(v, 3) for k, v in rows.items()},
        "repeats": REPEATS, "runs": {k: [round(v, 3) for v in values] for k, values in times.items()},
        "ratio_task_command_to_local_batch": round(rows["the task's command"] / rows["local batch"], 3),
        "ratio_one_task_to_local_batch": round(rows["one farm task"] / rows["local batch"], 3),
        "ratio_openjd_run_to_local_batch": round(rows["one farm task (openjd run)"] / rows["local batch"], 3),
        "ratio_task_per_input_to_local_batch": round(rows["one task per input"] / rows["local batch"], 3),
        "one_task_per_input_openjd_run_seconds": round(each_wall, 3),
        "task_outputs_equal_local_batch": same,
        "bundle_inputs": BUNDLE_INPUTS, "bundle_seconds": round(bundle_seconds, 3),
    }
    (out / "farm_bench.json").write_text(json.dumps(result, indent=2) + "\n")
    plot(result, out / "farm_bench.png")
    print(json.dumps(result, indent=2))


def plot(result: dict, path: Path) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    names, seconds = zip(*result["seconds"].items())
    fig, ax = plt.subplots(figsize=(7, 3.2))
    bars = ax.barh(names, seconds, color=["#4c72b0", "#8172b2", "#55a868", "#8fbf9a", "#c44e52"])
    for bar, value in zip(bars, seconds):
        ax.text(bar.get_width(), bar.get_y() + bar.get_height() / 2, f" {value:.1f} s", va="center")
    ax.set_xlabel(f"seconds for {result['inputs']} inputs ({' '.join(result['bake_options'])})")
    ax.set_title(f"Farm tasks against one local batch (bundle of {result['bundle_inputs']:,} inputs: "
                 f"{result['bundle_seconds']:.1f} s)", fontsize=10)
    ax.invert_yaxis()
    fig.tight_layout()
    fig.savefig(path, dpi=110)


if __name__ == "__main__":
    main()
