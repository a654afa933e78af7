# SPDX-License-Identifier: GPL-3.0-or-later
"""Incremental re-bake benchmark (issue 42): the time of re-baking only what an edit changed
(hao_addon/rebake.py) against a full bake of the edited scene, in one run, and how far the
incremental map lies from the full one.

    .venv/bin/python bench/rebake_bench.py [--out bench/results] [--sizes 2048,4096] [--quick]

Scene: a 20-unit floor (the target, 8,192 triangles, its own UVs) with 25 balls on it in a
5 x 5 grid. Edits: one ball of radius 0.1, 0.25 or 0.6 (added for the edit, beside the grid)
moved by a third of its radius; the share of texels each re-bakes is measured (at 256
directions half the stated RMSE is about one direction's weight, so every texel whose own
directions meet the moved ball is re-baked: 11.5 %, 49 % and 99.9 % at 2048^2 as first run). Per map size: the base bake (256 directions, Auto's method), then
per edit the incremental re-bake from it and the full bake of the edited scene (each once,
after one untimed bake of the base for the shaders), the share of texels re-baked, the
speed-up (full seconds / incremental seconds), and the largest |incremental - full| over the
kept texels (beside the report's bound on them) and over the re-baked ones (a GPU bake of some
texels fits its light views to them: the same estimate on another pixel grid, within the
stated error). Writes rebake_bench.json and
rebake_bench.png.
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

EDITS = {"ball r 0.1": 0.1, "ball r 0.25": 0.25, "ball r 0.6": 0.6}  # the moved ball's radius


def scene(edit_radius: float, moved: bool) -> tuple[TriangleSoup, list[TriangleSoup]]:
    floor = scenes.grid_plane(20.0, 64)
    floor = TriangleSoup(floor.positions, floor.uvs, "floor")
    balls = [scenes.uv_sphere(0.5, (x, y, 0.5), 24, 12, name=f"ball{i}{j}")
             for i, x in enumerate(np.linspace(-8, 8, 5)) for j, y in enumerate(np.linspace(-8, 8, 5))]
    shift = edit_radius / 3.0 if moved else 0.0
    edited = scenes.uv_sphere(edit_radius, (4.0 + shift, 4.0, edit_radius), 24, 12, name="edited")
    return floor, balls + [edited]


def timed(run, *args, **kwargs):
    t0 = time.perf_counter()
    out = run(*args, **kwargs)
    return time.perf_counter() - t0, out


def size_rows(size: int, directions: int) -> list[dict]:
    settings = BakeSettings(size=size, directions=directions)
    rows = []
    for label, radius in EDITS.items():
        target, occluders = scene(radius, False)
        bake(target, occluders, settings, use_cache=False)  # shaders compiled, caches warm
        base = bake(target, occluders, settings, use_cache=False)
        state = record(target, occluders, settings)
        edited_target, edited = scene(radius, True)
        incremental_s, (result, _state, report) = timed(rebake, base, state, edited_target, edited, settings)
        full_s, full = timed(bake, edited_target, edited, settings, use_cache=False)
        diff = np.abs(result.ao.astype(np.float64) - full.ao).reshape(-1)
        redo = np.zeros(diff.shape, bool)
        if report.cells is not None:
            redo[report.cells] = True
        covered = full.covered.reshape(-1)
        rows.append({"size": size, "edit": label, "moved_radius": radius, "rebaked_share": report.rebaked / report.covered,
                     "incremental_s": round(incremental_s, 3), "full_s": round(full_s, 3),
                     "speedup": round(full_s / incremental_s, 2),
                     "kept_max_difference": float(diff[covered & ~redo].max(initial=0.0)),
                     "rebaked_max_difference": float(diff[covered & redo].max(initial=0.0)),
                     "kept_bound": report.kept_bound, "threshold": report.threshold,
                     "stated_rmse": base.error.rmse, "method": full.method})
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
    ap.add_argument("--quick", action="store_true", help="512^2, 64 directions (a smoke test)")
    args = ap.parse_args()
    ensure_gpu_context()
    sizes = [512] if args.quick else [int(s) for s in args.sizes.split(",")]
    directions = 64 if args.quick else args.directions
    rows = [row for size in sizes for row in size_rows(size, directions)]
    results = {"machine": {"platform": platform.platform(), "python": platform.python_version(),
                           "blender": bpy.app.version_string},
               "directions": directions, "rows": rows}
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    (out / "rebake_bench.json").write_text(json.dumps(results, indent=2) + "\n")
    sys.path.insert(0, str(ROOT / "bench"))
    plot(results, out / "rebake_bench.png")
    return 0


if __name__ == "__main__":
    sys.exit(main())
