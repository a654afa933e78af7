# SPDX-License-Identifier: GPL-3.0-or-later
"""Bake-groups benchmark (issue 30): N name-matched low/high pairs, all in the same place,
baked by name in one process against each pair baked alone, in one run on one machine.

    .venv/bin/python bench/groups_bench.py [--pairs 8] [--out bench/results]

Each pair: a 4-unit low-poly plane over its own relief (a floor and a ball at a position of
its own), so every pair's map differs. Timed: the bake phase of the `--json` report (the
issue's target: the grouped run's at most 1.2x the sum of the single bakes'), and the whole
process (what one run instead of N saves: Blender's start, the GPU context, the shaders).
Each row REPEATS times, interleaved, medians kept. The grouped maps are checked equal to the
single ones. Writes groups_bench.json and groups_bench.png into the output folder.
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
BAKE = ["--size", "256", "--directions", "64", "--margin", "4"]
REPEATS = 3

MAKE_SCENE = r"""
import sys, bpy, numpy as np
sys.path.insert(0, sys.argv[-3])
from hao_addon.core import scenes
pairs, out = int(sys.argv[-2]), sys.argv[-1]
bpy.ops.wm.read_factory_settings(use_empty=True)

def link(soup, name):
    pos = soup.positions.reshape(-1, 3)
    verts, inverse = np.unique(pos, axis=0, return_inverse=True)
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata(verts.tolist(), [], inverse.reshape(-1, 3).tolist())
    if soup.uvs is not None:
        mesh.uv_layers.new(name="UVMap").uv.foreach_set("vector", soup.uvs.reshape(-1).astype(np.float32))
    mesh.update()
    obj = bpy.data.objects.new(name, mesh)
    bpy.context.scene.collection.objects.link(obj)

def pair(k):
    angle = 2 * np.pi * k / pairs
    link(scenes.grid_plane(4.0, 4, z=1.2, name=f"p{k}_low"), f"p{k}_low")
    link(scenes.uv_sphere(0.5, (np.cos(angle), np.sin(angle), 0.5), 48, 24, name=f"p{k}_high"), f"p{k}_high")
    link(scenes.grid_plane(200.0, 16, z=-0.001 * k, name=f"p{k}_high.001"), f"p{k}_high.001")

for k in range(pairs):
    pair(k)
bpy.ops.wm.save_as_mainfile(filepath=f"{out}/all.blend")
for k in range(pairs):
    bpy.ops.wm.read_factory_settings(use_empty=True)
    pair(k)
    bpy.ops.wm.save_as_mainfile(filepath=f"{out}/p{k}.blend")
"""


def hao(args: list, cwd: Path) -> tuple[float, dict]:
    """(wall seconds, the --json report) of one command, which must succeed."""
    report = cwd / "report.json"
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    t0 = time.perf_counter()
    done = subprocess.run([sys.executable, "-m", "hao_addon", *map(str, args), "--json", report],
                          capture_output=True, text=True, env=env, cwd=cwd)
    seconds = time.perf_counter() - t0
    if done.returncode != 0:
        raise SystemExit(f"{args[:3]} failed: {done.stderr[-2000:]}")
    return seconds, json.loads(report.read_text())


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--pairs", type=int, default=8)
    ap.add_argument("--out", default=str(ROOT / "bench" / "results"))
    opts = ap.parse_args()
    out = Path(opts.out)
    out.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory() as scratch:
        tmp = Path(scratch)
        subprocess.run([sys.executable, "-c", MAKE_SCENE, str(ROOT), str(opts.pairs), str(tmp)], check=True,
                       capture_output=True)
        runs = {"grouped bake phase": [], "single bake phases summed": [], "grouped process": [],
                "single processes summed": []}
        for k in range(REPEATS):
            (tmp / f"g{k}").mkdir()
            (tmp / f"s{k}").mkdir()
            wall, report = hao(["bake", tmp / "all.blend", "--out", tmp / f"g{k}" / "{object}.png", "--match-names",
                                *BAKE], tmp)
            runs["grouped process"].append(wall)
            runs["grouped bake phase"].append(report["timings"]["bake"])
            walls, phases = 0.0, 0.0
            for p in range(opts.pairs):
                wall, report = hao(["bake", tmp / f"p{p}.blend", "--out", tmp / f"s{k}" / f"p{p}_low.png",
                                    "--object", f"p{p}_low", "--high-poly", f"p{p}_high", "--high-poly",
                                    f"p{p}_high.001", "--occluders", "target", *BAKE], tmp)
                walls, phases = walls + wall, phases + report["timings"]["bake"]
            runs["single processes summed"].append(walls)
            runs["single bake phases summed"].append(phases)
        same = all(_pixels(tmp / "g0" / f"p{p}_low.png") == _pixels(tmp / "s0" / f"p{p}_low.png")
                   for p in range(opts.pairs))
    rows = {name: statistics.median(values) for name, values in runs.items()}
    result = {
        "machine": {"platform": platform.platform(), "cpus": os.cpu_count(), "python": sys.version.split()[0]},
        "pairs": opts.pairs, "bake_options": BAKE, "repeats": REPEATS,
        "seconds": {k: round(v, 3) for k, v in rows.items()},
        "runs": {k: [round(v, 3) for v in values] for k, values in runs.items()},
        "ratio_bake_phase": round(rows["grouped bake phase"] / rows["single bake phases summed"], 3),
        "ratio_process": round(rows["grouped process"] / rows["single processes summed"], 3),
        "grouped_maps_equal_single": same,
    }
    (out / "groups_bench.json").write_text(json.dumps(result, indent=2) + "\n")
    plot(result, out / "groups_bench.png")
    print(json.dumps(result, indent=2))


def _pixels(path: Path) -> bytes:
    """The decoded pixels of a PNG (its metadata, the bake key, differs between the runs)."""
    import bpy
    import numpy as np
    image = bpy.data.images.load(str(path), check_existing=False)
    try:
        pixels = np.empty(len(image.pixels), np.float32)
        image.pixels.foreach_get(pixels)
        return pixels.tobytes()
    finally:
        bpy.data.images.remove(image)


def plot(result: dict, path: Path) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    names, seconds = zip(*result["seconds"].items())
    fig, ax = plt.subplots(figsize=(7, 3.0))
    bars = ax.barh(names, seconds, color=["#55a868", "#4c72b0", "#8fbf9a", "#8da0cb"])
    for bar, value in zip(bars, seconds):
        ax.text(bar.get_width(), bar.get_y() + bar.get_height() / 2, f" {value:.1f} s", va="center")
    ax.set_xlabel(f"seconds for {result['pairs']} name-matched pairs ({' '.join(result['bake_options'])})")
    ax.set_title(f"Bake groups: one run against each pair alone (bake phase {result['ratio_bake_phase']:.2f}x)",
                 fontsize=10)
    ax.invert_yaxis()
    fig.tight_layout()
    fig.savefig(path, dpi=110)


if __name__ == "__main__":
    main()
