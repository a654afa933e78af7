# SPDX-License-Identifier: GPL-3.0-or-later
"""Cycles' time to a stated error, beside HAO's bake to that error (bench/error_bench.py), in
the same scenes: the smooth rocker arm and smooth Spot at 256^2 in the layouts of Cycles'
truths.

    .venv/bin/python bench/cycles_error_bench.py [--out bench/results]

Cycles' error here is its statistical error, as HAO's estimate is: each bake against its own
converged value. Two seeds at each sample count differ by sqrt(2) times one bake's error, so
|a - b| / sqrt(2) is a draw of it, and its 99th percentile is one bake's p99. The rate at which
that p99 falls is measured between 256 and 1024 samples; the samples and seconds that would
reach half an 8-bit step (1/510) are predicted from it, and then Cycles bakes that many samples
(two seeds again) to measure the p99 and the time it reached. Writes cycles_error_bench.json.
"""
from __future__ import annotations

import argparse
import json
import math
import platform
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path[:0] = [str(ROOT), str(ROOT / "tests"), str(ROOT / "tools")]

import bpy  # noqa: E402
import numpy as np  # noqa: E402

import shading_scenes as cases  # noqa: E402
from cycles_bake import cycles_ao_bake  # noqa: E402

MESHES = ["rocker_smooth", "spot_smooth"]
TARGET = 0.5 / 255.0
SAMPLES = [256, 1024]


def bakes(name: str, seed: int, samples: list[int]) -> list[tuple[int, float, np.ndarray]]:
    bpy.ops.wm.read_factory_settings(use_empty=True)
    truth = np.load(cases.truth_path(name))
    obj = cases.build_object(name, truth["uvs"].astype(np.float64))
    return cycles_ao_bake(obj, cases.TRUTH_SIZE, samples, seed=seed, warm_up=True, log=True)


def measured(first, second) -> list[dict]:
    """One bake's p99 and RMSE (from two seeds) and the faster seed's seconds per sample count."""
    rows = []
    for (n, seconds, a), (_n, seconds_b, b) in zip(first, second):
        found = (a > 0) & (b > 0)  # Cycles leaves texels it does not bake black
        noise = np.abs(a[found].astype(np.float64) - b[found]) / math.sqrt(2.0)
        rows.append(dict(samples=n, seconds=min(seconds, seconds_b), p99=float(np.percentile(noise, 99)),
                         rmse=float(np.sqrt((noise ** 2).mean()))))
    return rows


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--out", default=str(ROOT / "bench" / "results"))
    args = ap.parse_args()
    out = Path(args.out)
    hao = json.loads((out / "error_bench.json").read_text())["meshes"]
    results = dict(machine=platform.platform(), target_p99=TARGET, samples=SAMPLES, meshes={})
    for name in MESHES:
        rows = measured(bakes(name, 0, SAMPLES), bakes(name, 1, SAMPLES))
        rate = math.log(rows[0]["p99"] / rows[1]["p99"]) / math.log(SAMPLES[1] / SAMPLES[0])
        samples = int(math.ceil(SAMPLES[1] * (rows[1]["p99"] / TARGET) ** (1.0 / rate)))
        at_target = measured(bakes(name, 0, [samples]), bakes(name, 1, [samples]))[0]
        ours = hao[name]["to_error"]["seconds"]
        results["meshes"][name] = dict(bakes=rows, rate=rate, at_target=at_target, hao_to_target_seconds=ours,
                                       speedup=at_target["seconds"] / ours)
        print(f"{name}: Cycles p99 {rows[0]['p99']:.4f} / {rows[1]['p99']:.4f} at {SAMPLES} samples, rate "
              f"{rate:.2f}; {samples} samples: p99 {at_target['p99']:.5f} in {at_target['seconds']:.0f} s; HAO to p99 "
              f"{TARGET:.5f} {ours:.1f} s ({at_target['seconds'] / ours:.1f}x)", flush=True)
    (out / "cycles_error_bench.json").write_text(json.dumps(results, indent=1))


if __name__ == "__main__":
    main()
