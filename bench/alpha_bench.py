# SPDX-License-Identifier: GPL-3.0-or-later
"""Alpha-aware occluders benchmark (issue 30): accuracy and time of the card scenes on both
GPU methods against the reference, and what a scene without alpha pays, in one run.

    .venv/bin/python bench/alpha_bench.py [--out bench/results]

Scenes (tests/test_alpha.py's): a 4-unit floor under a near-infinite card of alpha 0.5 at
height 0.5 (truth 0.5 everywhere), and under a 2-unit card whose alpha texture clips its left
half (truth: the reference's map of the same scene, 32^2). Rows per GPU method and direction
count: bake seconds (median of REPEATS, after one untimed bake for the shaders) and RMSE
against the truth. Then the opaque card scene timed with alpha data that lets nothing
through (the plain passes, as without alpha) against no alpha data at all: the issue's
"costs the same as today". Writes alpha_bench.json and alpha_bench.png.
"""
from __future__ import annotations

import argparse
import json
import os
import platform
import statistics
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "tests"))

import bpy  # noqa: E402,F401 - the GPU context and mathutils

from hao_addon.bake import bake  # noqa: E402
from hao_addon.gpu.context import ensure_gpu_context  # noqa: E402
from hao_addon.core.bake.alpha import SoupAlpha  # noqa: E402
from hao_addon.core.bake.settings import BakeSettings  # noqa: E402
from hao_addon.core.geometry import TriangleSoup  # noqa: E402
from test_alpha import _textured_card, card, floor  # noqa: E402

REPEATS = 3
SIZE = 128


def timed(occluders: list, settings: BakeSettings) -> tuple[float, object]:
    bake(floor(), occluders, settings, use_cache=False)  # shaders compiled, untimed
    runs, result = [], None
    for _ in range(REPEATS):
        t0 = time.perf_counter()
        result = bake(floor(), occluders, settings, use_cache=False)
        runs.append(time.perf_counter() - t0)
    return statistics.median(runs), result


def rmse(result, truth: np.ndarray) -> float:
    mask = result.covered
    return float(np.sqrt(((result.ao[mask] - truth[mask]) ** 2).mean()))


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--out", default=str(ROOT / "bench" / "results"))
    out = Path(ap.parse_args().out)
    out.mkdir(parents=True, exist_ok=True)
    ensure_gpu_context()
    textured, _cut = _textured_card()
    ref_settings = BakeSettings(size=32, directions=1024, method="reference", margin=0, alpha="clip")
    reference = bake(floor(), [textured], ref_settings, use_cache=False).ao
    clipped_truth = np.kron(reference, np.ones((SIZE // 32, SIZE // 32), np.float32))  # nearest up-sampling
    rows = []
    for method in ("scatter", "gather"):
        for directions in (256, 1024):
            s = BakeSettings(size=SIZE, directions=directions, method=method, margin=0)
            seconds, res = timed([card(0.5)], s)
            rows.append(dict(scene="card 50 %", method=method, directions=directions, seconds=round(seconds, 3),
                             rmse=round(rmse(res, np.full(res.ao.shape, 0.5, np.float32)), 4)))
            clip = BakeSettings(size=SIZE, directions=directions, method=method, margin=0, alpha="clip")
            seconds, res = timed([textured], clip)
            rows.append(dict(scene="clipped texture card", method=method, directions=directions,
                             seconds=round(seconds, 3), rmse=round(rmse(res, clipped_truth), 4)))
    plain = TriangleSoup(card(0.5).positions, None, "card")
    opaque = TriangleSoup(plain.positions, None, "card", alpha=SoupAlpha(np.ones(plain.face_count, np.float32)))
    costs = {}
    for method in ("scatter", "gather"):
        s = BakeSettings(size=SIZE, directions=256, method=method, margin=0)
        no_data, _ = timed([plain], s)
        all_opaque, res = timed([opaque], s)
        costs[method] = dict(no_alpha_data=round(no_data, 3), alpha_lets_nothing_through=round(all_opaque, 3),
                             ratio=round(all_opaque / no_data, 3), alpha_faces=res.stats["alpha_faces"])
    result = {"machine": {"platform": platform.platform(), "cpus": os.cpu_count(), "python": sys.version.split()[0],
                          "blender": bpy.app.version_string},
              "size": SIZE, "repeats": REPEATS, "rows": rows, "without_alpha": costs,
              "clip_truth": "reference, 32^2, 1024 directions"}
    (out / "alpha_bench.json").write_text(json.dumps(result, indent=2) + "\n")
    plot(result, out / "alpha_bench.png")
    print(json.dumps(result, indent=2))


def plot(result: dict, path: Path) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 2, figsize=(9, 3.4))
    for ax, scene in zip(axes, ("card 50 %", "clipped texture card")):
        for method, colour in (("scatter", "#4c72b0"), ("gather", "#55a868")):
            pts = [(r["seconds"], r["rmse"], r["directions"]) for r in result["rows"]
                   if r["scene"] == scene and r["method"] == method]
            ax.plot([p[0] for p in pts], [p[1] for p in pts], "o-", color=colour, label=method)
            for x, y, d in pts:
                ax.annotate(str(d), (x, y), textcoords="offset points", xytext=(4, 4), fontsize=7)
        ax.axhline(0.02, color="#c44e52", ls="--", lw=1, label="target 0.02")
        ax.set_title(scene, fontsize=10)
        ax.set_xlabel("bake seconds")
        ax.set_ylabel("RMSE")
        ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=110)


if __name__ == "__main__":
    main()
