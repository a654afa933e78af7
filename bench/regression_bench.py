# SPDX-License-Identifier: GPL-3.0-or-later
"""Same-run regression check of the bake against an earlier revision (issue 30's target: the
flat, smooth and Selected-to-Active rows get neither slower nor less accurate).

    .venv/bin/python bench/regression_bench.py --base REV [--rounds 4] [--out bench/results]

Both revisions bake the same inputs (written once here, so xatlas and normals cannot differ)
in separate processes, alternated --rounds times (which goes first alternates too): the rocker arm flat and shaded smooth on both
GPU methods, and the bunny pair (Selected to Active, tests/data's low-poly) on the gather.
Each process bakes every case once untimed (shaders), then REPEATS times; medians are kept,
and every run's seconds are in the JSON (the machine is shared: judge a ratio by its spread);
fastest_ratio compares the fastest runs, which interference from other work slows least.
Accuracy: the maps of the two revisions are compared texel for texel (equal maps bake equal
errors against any truth). Writes regression_bench.json.
"""
from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
ROUNDS = 4
REPEATS = 3

WORKER = r"""
import json, sys, time
import numpy as np
import bpy
from hao_addon.bake import HighToLow, bake
try:
    from hao_addon.gpu.context import ensure_gpu_context
except ImportError:  # a revision before the GPU context moved (13a9a82 and earlier)
    from hao_addon.blender.gpu_context import ensure_gpu_context
from hao_addon.core.bake.settings import BakeSettings
from hao_addon.core.geometry import TriangleSoup
inputs, out, repeats = sys.argv[-3], sys.argv[-2], int(sys.argv[-1])
ensure_gpu_context()
d = np.load(inputs)
rocker = TriangleSoup(d["rocker_pos"], d["rocker_uv"], "rocker")
smooth = TriangleSoup(d["rocker_pos"], d["rocker_uv"], "rocker", d["rocker_normals"])
low = TriangleSoup(d["low_pos"], d["low_uv"], "low", d["low_normals"])
high = TriangleSoup(d["high_pos"], None, "high", d["high_normals"])
cases = {
    "flat rocker, scatter": (rocker, {}, dict(method="scatter", normals="face")),
    "flat rocker, gather": (rocker, {}, dict(method="gather", normals="face")),
    "smooth rocker, scatter": (smooth, {}, dict(method="scatter")),
    "smooth rocker, gather": (smooth, {}, dict(method="gather")),
    "bunny pair, gather": (low, {"high_to_low": HighToLow([high])},
                           dict(method="gather", cage_extrusion=0.005, max_ray_distance=0.02)),
}
times, maps = {}, {}
for name, (target, extra, kw) in cases.items():
    settings = BakeSettings(size=512, directions=256, margin=0, **kw)
    bake(target, [], settings, use_cache=False, **extra)
    runs = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        res = bake(target, [], settings, use_cache=False, **extra)
        runs.append(time.perf_counter() - t0)
    times[name] = runs
    maps[name.replace(" ", "_").replace(",", "")] = res.ao
np.savez(out + ".npz", **maps)
open(out + ".json", "w").write(json.dumps(times))
"""


def vertex_normals(positions: np.ndarray) -> np.ndarray:
    """(F, 3, 3) area-weighted vertex normals of a soup (vertices welded by position)."""
    flat = positions.reshape(-1, 3)
    _unique, index = np.unique(flat.round(9), axis=0, return_inverse=True)
    index = index.ravel()
    face = np.cross(positions[:, 1] - positions[:, 0], positions[:, 2] - positions[:, 0])
    sums = np.zeros((index.max() + 1, 3))
    np.add.at(sums, index, np.repeat(face, 3, axis=0))
    sums /= np.maximum(np.linalg.norm(sums, axis=1, keepdims=True), 1e-30)
    return sums[index].reshape(-1, 3, 3)


def write_inputs(path: Path) -> None:
    sys.path.insert(0, str(ROOT))
    from hao_addon.core.objfile import obj_soup, read_obj
    rocker_soup = obj_soup(ROOT / "tests" / "data" / "rocker-arm.obj", uvs="auto", size=512)
    rocker = rocker_soup.positions
    pair = np.load(ROOT / "tests" / "data" / "cycles_bunny_high_to_low.npz")
    low = pair["low_vertices"][pair["low_triangles"]]
    hv, ht, _huv, _htu = read_obj(ROOT / "bench" / "data" / "stanford-bunny.obj")
    high = hv[ht]
    np.savez(path, rocker_pos=rocker, rocker_uv=rocker_soup.uvs, rocker_normals=vertex_normals(rocker),
             low_pos=low, low_uv=pair["uvs"], low_normals=vertex_normals(low), high_pos=high,
             high_normals=vertex_normals(high))


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--base", required=True, help="the earlier revision to compare against")
    ap.add_argument("--out", default=str(ROOT / "bench" / "results"))
    ap.add_argument("--rounds", type=int, default=ROUNDS)
    opts = ap.parse_args()
    out = Path(opts.out)
    out.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory() as scratch:
        tmp = Path(scratch)
        base_tree = tmp / "base"
        subprocess.run(["git", "-C", str(ROOT), "worktree", "add", "--detach", str(base_tree), opts.base], check=True,
                       capture_output=True)
        try:
            write_inputs(tmp / "inputs.npz")
            trees = {"base": base_tree, "head": ROOT}
            times = {name: {} for name in trees}
            for k in range(opts.rounds):
                for name, tree in (list(trees.items()) if k % 2 == 0 else list(trees.items())[::-1]):
                    env = {**os.environ, "PYTHONPATH": str(tree)}
                    stem = str(tmp / f"{name}{k}")
                    done = subprocess.run([sys.executable, "-c", WORKER, str(tmp / "inputs.npz"), stem, str(REPEATS)],
                                          env=env, cwd=tmp, capture_output=True, text=True)
                    if done.returncode != 0:
                        raise SystemExit(f"{name} ({tree}) failed:\n{done.stderr[-3000:]}")
                    for case, runs in json.loads(Path(stem + ".json").read_text()).items():
                        times[name].setdefault(case, []).extend(runs)
            base_maps, head_maps = np.load(tmp / "base0.npz"), np.load(tmp / "head0.npz")
            rows = {}
            for case in times["head"]:
                key = case.replace(" ", "_").replace(",", "")
                base_s, head_s = statistics.median(times["base"][case]), statistics.median(times["head"][case])
                diff = np.abs(head_maps[key].astype(np.float64) - base_maps[key])
                rows[case] = dict(base_seconds=round(base_s, 3), head_seconds=round(head_s, 3),
                                  ratio=round(head_s / base_s, 3),
                                  fastest_ratio=round(min(times["head"][case]) / min(times["base"][case]), 3),
                                  max_abs_map_difference=float(diff.max()),
                                  base_runs=[round(t, 3) for t in times["base"][case]],
                                  head_runs=[round(t, 3) for t in times["head"][case]],
                                  maps_equal=bool((diff == 0).all()))
        finally:
            subprocess.run(["git", "-C", str(ROOT), "worktree", "remove", "--force", str(base_tree)],
                           capture_output=True)
    result = dict(base=opts.base, head=subprocess.run(["git", "-C", str(ROOT), "rev-parse", "--short", "HEAD"],
                                                      capture_output=True, text=True).stdout.strip(),
                  size=512, directions=256, rounds=opts.rounds, repeats=REPEATS, rows=rows)
    (out / "regression_bench.json").write_text(json.dumps(result, indent=2) + "\n")
    print(json.dumps(result, indent=2))


if __name__ == "__main__":
    main()
