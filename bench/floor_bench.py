# SPDX-License-Identifier: GPL-3.0-or-later
"""Whether a bake's stated error is its whole error: every method's maps against the
independent truth (bench/truth.py: Embree, converged), by direction count, on Spot, the rocker
arm, the bunny and fandisk, flat and smooth, in one run.

    .venv/bin/python bench/floor_bench.py [--meshes ...] [--size 128] [--rays 32768]
        [--methods gather,reference,scatter] [--carry bench/results/floor_bench.json]

Each map is measured against the truth that matches what its texels are:
- the gather: the AO at each texel's sample point, where its GPU texel list put it
  (truth.bake_sample_points: the texel centre, on the face its rasterizer picked);
- the reference: the AO at the texel centre on the face the CPU raster picks (texel_samples);
- the scatter: the average over each texel's covered area (truth at an AREA_GRID x AREA_GRID
  grid of points per texel, averaged over the covered ones), at every texel a UV triangle covers.
Smooth rows shade with Blender's smooth corner normals and Cycles' terminator offset (the
truth lifts its rays the same way). Per row: measured RMSE (the truth's own noise taken out)
and p99 against the truth, the bake's stated RMSE and p99, their ratios (measured / stated),
and the visibility floor the bake measured in it (hao_addon/floor_check.py). The reference
runs up to 1024 directions (its rays are a Python call each), and takes most of the run's
time: --methods reruns the methods a change touches, and --carry keeps an earlier run's rows of
the others (the file names each carried method's revision). Writes floor_bench.json into the
output folder.
"""
from __future__ import annotations

import argparse
import json
import platform
import sys
import time
from dataclasses import replace
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "bench"))

import numpy as np  # noqa: E402

from truth import Truth, bake_sample_points, reference_sample_points, texel_samples, truth_at  # noqa: E402

MESHES = (ROOT / "tests" / "data" / "spot.obj", ROOT / "tests" / "data" / "rocker-arm.obj",
          ROOT / "bench" / "data" / "stanford-bunny.obj", ROOT / "tests" / "data" / "fandisk.obj")
DIRECTIONS = {"gather": (64, 256, 1024, 4096, 16384), "scatter": (64, 256, 1024, 4096),
              "reference": (64, 256, 1024)}
# The scatter's truth: points per texel side. A 4 x 4 grid was itself 0.0047 RMS off the
# texel-area averages (the flat rocker arm at 128^2, against a 16 x 16 grid; p99 0.018, most
# in part-covered texels): as large as the scatter's whole error at 4096 directions, which it
# then read as under-stated (1.17 RMSE, 1.29 p99; 0.92 against the 16 x 16 grid). 8 x 8 is
# within the truths' own noise of 16 x 16 (0.0021 RMS, noise 0.0024).
AREA_GRID = 8


def area_truth(soup, size: int, rays: int, shading: bool, terminator_offset: float = 0.0) -> Truth:
    """The truth of texel-area averages: AREA_GRID^2 points per texel, rays / AREA_GRID^2 each."""
    fine = texel_samples(soup, size * AREA_GRID, shading, terminator_offset)
    t = truth_at(soup, [], fine, rays=max(2, rays // AREA_GRID ** 2))
    k = AREA_GRID
    cover = t.covered.reshape(size, k, size, k).sum(axis=(1, 3))
    total = (t.values * t.covered).reshape(size, k, size, k).sum(axis=(1, 3))
    values = np.divide(total, cover, out=np.zeros(total.shape), where=cover > 0)
    # Every texel a UV triangle covers, part-covered ones at chart borders too: the scatter's
    # value there is the average over the covered part, which the covered grid points sample.
    # (Interior texels alone left out where its floor sits: on the rocker arm at 1024
    # directions the checked interior texels shared none of it, and the bake over-stated by 2x.)
    covered = cover > 0
    return Truth(values, covered, t.noise * float(np.sqrt(np.mean(1.0 / cover[covered]))))  # c points: sigma / sqrt(c)


def truths(soup, settings, rays: int, methods: tuple[str, ...]) -> dict:
    """The matching truth of each of `methods` (see the module docstring)."""
    smooth = soup.normals is not None
    make = {"gather": lambda: truth_at(soup, [], bake_sample_points(soup, settings), rays=rays),
            "reference": lambda: truth_at(soup, [], reference_sample_points(soup, settings), rays=rays),
            "scatter": lambda: area_truth(soup, settings.size, rays, smooth, settings.terminator_offset)}
    return {method: make[method]() for method in methods}


def row(result, truth: Truth) -> dict:
    both = result.covered & truth.covered
    error = result.ao[both] - truth.values[both]
    rmse = float(np.sqrt(max(np.mean(error ** 2) - truth.noise ** 2, 0.0)))
    p99 = float(np.quantile(np.abs(error), 0.99))
    stated = result.error
    return {"measured_rmse": rmse, "measured_p99": p99, "bias": float(error.mean()),
            "stated_rmse": stated.rmse, "stated_p99": stated.p99,
            "rmse_ratio": rmse / stated.rmse, "p99_ratio": p99 / stated.p99,
            "floor_rmse": stated.floor_rmse, "floor_p99": stated.floor_p99, "floor_texels": stated.floor_texels,
            "texels": int(both.sum())}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--meshes", nargs="+", default=[str(p) for p in MESHES])
    ap.add_argument("--size", type=int, default=128)
    ap.add_argument("--rays", type=int, default=32768)
    ap.add_argument("--methods", default="gather,reference,scatter")
    ap.add_argument("--view-samples", type=float, default=2.0)
    ap.add_argument("--out", default=str(ROOT / "bench" / "results"))
    ap.add_argument("--carry", metavar="FILE", help="an earlier floor_bench.json whose rows of the methods not "
                    "run now are kept (marked in 'carried'): rerun the methods a change touches")
    args = ap.parse_args()
    revision = _revision()  # the code that runs: taken before the run, which may outlast a commit
    from hao_addon.gpu.context import ensure_gpu_context
    ensure_gpu_context()
    from hao_addon.bake import bake
    from hao_addon.core.bake.settings import BakeSettings
    from hao_addon.core.geometry import smooth_vertex_normals
    from hao_addon.core.objfile import obj_soup
    rows, truth_info = [], {}
    for mesh in args.meshes:
        try:
            flat = obj_soup(mesh)
        except ValueError:  # no UVs: unwrapped as a bake unwraps them
            flat = obj_soup(mesh, uvs="auto", size=args.size)
        for shading, soup in (("flat", flat), ("smooth", replace(flat, normals=smooth_vertex_normals(flat.positions)))):
            name = f"{Path(mesh).stem} {shading}"
            settings = BakeSettings(size=args.size, margin=0, normals="mesh" if shading == "smooth" else "face",
                                    view_samples=args.view_samples)
            start = time.perf_counter()
            matching = truths(soup, settings, args.rays, tuple(args.methods.split(",")))
            truth_info[name] = {m: {"texels": int(t.covered.sum()), "noise_rmse": t.noise} for m, t in matching.items()}
            truth_info[name]["seconds"] = time.perf_counter() - start
            print(f"truths of {name}: {truth_info[name]}", flush=True)
            for method in args.methods.split(","):
                for directions in DIRECTIONS[method]:
                    start = time.perf_counter()
                    result = bake(soup, [], replace(settings, method=method, directions=directions), use_cache=False)
                    rows.append({"mesh": Path(mesh).stem, "shading": shading, "method": method,
                                 "directions": directions, "seconds": time.perf_counter() - start,
                                 **row(result, matching[method])})
                    print(json.dumps(rows[-1]), flush=True)
    import bpy
    result = {"size": args.size, "view_samples": args.view_samples, "revision": revision,
              "truth": {"rays": args.rays, "tracer": "Embree (embreex)", "meshes": truth_info},
              "machine": {"platform": platform.platform(), "python": platform.python_version(),
                          "blender": bpy.app.version_string},
              "rows": rows}
    if args.carry:
        result = carried(result, json.loads(Path(args.carry).read_text()))
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    (out / "floor_bench.json").write_text(json.dumps(result, indent=1) + "\n")


def carried(result: dict, earlier: dict) -> dict:
    """result with the rows of `earlier` whose method it did not run, and in result["carried"]
    each carried method's revision (the earlier file's own "carried" entries stay theirs)."""
    ran = {r["method"] for r in result["rows"]}
    rows = [r for r in earlier["rows"] if r["method"] not in ran]
    before = earlier.get("carried", {})
    origin = {m: before.get(m, earlier.get("revision", "unrecorded")) for m in sorted({r["method"] for r in rows})}
    return {**result, "rows": result["rows"] + rows, "carried": {**origin}}


def _revision() -> str:
    """The checkout's short commit, with '+' when it has uncommitted changes."""
    import subprocess
    head = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=ROOT, capture_output=True, text=True).stdout.strip()
    dirty = subprocess.run(["git", "status", "--porcelain", "--untracked-files=no"], cwd=ROOT, capture_output=True,
                           text=True).stdout.strip()
    return head + ("+" if dirty else "")


if __name__ == "__main__":
    main()
