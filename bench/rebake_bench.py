# SPDX-License-Identifier: GPL-3.0-or-later
"""Incremental re-bake benchmark (issue 42): the time of re-baking only what an edit changed
(hao_addon/rebake.py) against a whole bake of the edited scene, in one run, and how far the
incremental map lies from the whole one.

    .venv/bin/python bench/rebake_bench.py [--out bench/results] [--sizes 2048,4096] [--repeats 3] [--quick]

Scene: a 20-unit floor (the target, 8,192 triangles, its own UVs) with 25 balls of radius
0.5 in a 5 x 5 grid, and three smaller balls between them. Each edit moves one of those by a
third of its radius: radius 0.1, 0.25 and 0.7, chosen to re-bake about 1 %, 5 % and 25 % of
the texels at 256 directions and unlimited distance (every texel some of whose own directions
can meet the ball before or after: long, thin streaks across the floor, not a patch). Per map
size: one whole bake of the base scene (Auto's method: the gather), then per edit the
incremental re-bake from it and the whole bake of the edited scene, alternated `--repeats`
times (after one untimed bake for the shaders; a whole bake's time alone varies by up to
1.4x between runs on a shared machine): the share of texels re-baked, the median times, the
speed-up (median whole seconds / median incremental seconds, and the range of the repeats'
own ratios), the largest |incremental - whole| over the kept texels beside the
report's bound on them, and over the re-baked ones (float rounding: the gather re-bakes them
by difference, tests/test_rebake_difference.py), and how they were baked. Writes
rebake_bench.json and rebake_bench.png.
"""
from __future__ import annotations

import argparse
import json
import platform
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

import bpy  # noqa: E402

from hao_addon.bake import bake  # noqa: E402
from hao_addon.core import scenes  # noqa: E402
from hao_addon.core.bake.settings import BakeSettings  # noqa: E402
from hao_addon.core.geometry import TriangleSoup  # noqa: E402
from hao_addon.gpu.context import ensure_gpu_context  # noqa: E402
from hao_addon.rebake import rebake, record  # noqa: E402

EDITS = {"ball r 0.1": (0.1, (4.0, 4.5)), "ball r 0.25": (0.25, (-2.0, 4.5)),
         "ball r 0.7": (0.7, (2.0, -4.5))}  # the moved ball: its radius and where it stands


def scene(moved: str | None = None) -> tuple[TriangleSoup, list[TriangleSoup]]:
    """The floor and its occluders, with the ball of edit `moved` moved by a third of its radius."""
    floor = scenes.grid_plane(20.0, 64)
    floor = TriangleSoup(floor.positions, floor.uvs, "floor")
    balls = [scenes.uv_sphere(0.5, (x, y, 0.5), 24, 12, name=f"ball{i}{j}")
             for i, x in enumerate(np.linspace(-8, 8, 5)) for j, y in enumerate(np.linspace(-6, 6, 5))]
    for label, (radius, (x, y)) in EDITS.items():
        shift = radius / 3.0 if label == moved else 0.0
        balls.append(scenes.uv_sphere(radius, (x + shift, y, radius), 24, 12, name=label))
    return floor, balls


def timed(run, *args, **kwargs):
    t0 = time.perf_counter()
    out = run(*args, **kwargs)
    return time.perf_counter() - t0, out


def size_rows(size: int, directions: int, repeats: int) -> list[dict]:
    settings = BakeSettings(size=size, directions=directions)
    target, occluders = scene()
    bake(target, occluders, settings, use_cache=False)  # shaders compiled, caches warm
    base_s, base = timed(bake, target, occluders, settings, use_cache=False)
    state = record(target, occluders, settings)
    rows = []
    for label, (radius, _where) in EDITS.items():
        edited_target, edited = scene(label)
        incremental, whole = [], []
        for _ in range(repeats):  # alternated: a slow spell of the machine slows both
            seconds, (result, _state, report) = timed(rebake, base, state, edited_target, edited, settings)
            incremental.append(seconds)
            seconds, full = timed(bake, edited_target, edited, settings, use_cache=False)
            whole.append(seconds)
        incremental_s, full_s = float(np.median(incremental)), float(np.median(whole))
        ratios = [w / i for w, i in zip(whole, incremental)]
        diff = np.abs(result.ao.astype(np.float64) - full.ao).reshape(-1)
        redo = np.zeros(diff.shape, bool)
        if report.cells is not None:
            redo[report.cells] = True
        covered = full.covered.reshape(-1)
        rows.append({"size": size, "edit": label, "moved_radius": radius, "rebaked_share": report.rebaked / report.covered,
                     "incremental_s": round(incremental_s, 3), "full_s": round(full_s, 3), "base_s": round(base_s, 3),
                     "speedup": round(full_s / incremental_s, 2),
                     "speedup_range": [round(min(ratios), 2), round(max(ratios), 2)],
                     "incremental_runs_s": [round(s, 3) for s in incremental],
                     "full_runs_s": [round(s, 3) for s in whole],
                     "kept_max_difference": float(diff[covered & ~redo].max(initial=0.0)),
                     "rebaked_max_difference": float(diff[covered & redo].max(initial=0.0)),
                     "kept_bound": report.kept_bound, "threshold": report.threshold,
                     "stated_rmse": base.error.rmse, "rebaked_stated_rmse": result.error.rmse, "method": full.method,
                     "how": report.how})
        print(json.dumps(rows[-1]), flush=True)
    return rows


def plot(results: dict, path: Path) -> None:
    from plot_grid import panel_grid, save
    fig, (ax,) = panel_grid(1)
    for size in sorted({r["size"] for r in results["rows"]}):
        rows = [r for r in results["rows"] if r["size"] == size]
        ax.plot([100 * r["rebaked_share"] for r in rows], [r["speedup"] for r in rows], "o-", label=f"{size}^2")
    ax.axhline(10.0, color="gray", ls="--", lw=0.8)
    ax.set_xscale("log")
    ax.set_xlabel("texels re-baked (%)")
    ax.set_ylabel("speed-up: full bake s / incremental s")
    ax.set_title("Incremental re-bake against a full bake of the edited scene")
    ax.legend(fontsize=8)
    save(fig, path)


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--out", default=str(ROOT / "bench" / "results"))
    ap.add_argument("--sizes", default="2048,4096")
    ap.add_argument("--directions", type=int, default=256)
    ap.add_argument("--repeats", type=int, default=3, help="timed pairs per edit (medians reported)")
    ap.add_argument("--quick", action="store_true", help="512^2, 64 directions (a smoke test)")
    args = ap.parse_args()
    ensure_gpu_context()
    sizes = [512] if args.quick else [int(s) for s in args.sizes.split(",")]
    directions = 64 if args.quick else args.directions
    repeats = 1 if args.quick else max(1, args.repeats)
    rows = [row for size in sizes for row in size_rows(size, directions, repeats)]
    results = {"machine": {"platform": platform.platform(), "python": platform.python_version(),
                           "blender": bpy.app.version_string},
               "directions": directions, "repeats": repeats, "rows": rows}
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    (out / "rebake_bench.json").write_text(json.dumps(results, indent=2) + "\n")
    sys.path.insert(0, str(ROOT / "bench"))
    plot(results, out / "rebake_bench.png")
    return 0


if __name__ == "__main__":
    sys.exit(main())
