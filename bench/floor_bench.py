# SPDX-License-Identifier: GPL-3.0-or-later
"""Where a bake's error stops falling: the gather's maps against the independent
truth (bench/truth.py: Embree, at each texel centre), by direction count and light-view
resolution (view samples), in one run.

    .venv/bin/python bench/floor_bench.py [--meshes samples/spot.obj ...] [--size 128] [--rays 8192]

Meshes: Spot, the rocker arm, the bunny and fandisk, flat (normals 'face'); those without UVs
are unwrapped as a bake unwraps them.

Per row: the measured RMSE, p99 and bias against the truth, the same without the worst 0.2 %
of the texels (the tail: texel centres on UV edges between triangles of other normals, where
the bake and the truth may pick other triangles), the bake's stated RMSE and p99, and how
the squared error splits between the tail and the rest. The truth's own noise is reported
(two seeds); it is taken out of the measured RMSE (sqrt(measured^2 - noise^2)).
Writes floor_bench.json into the output folder.
"""
from __future__ import annotations

import argparse
import json
import platform
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "bench"))

import numpy as np  # noqa: E402

from truth import texel_truth  # noqa: E402

TAIL = 0.002  # the worst share of texels reported apart
MESHES = (ROOT / "samples" / "spot.obj", ROOT / "tests" / "data" / "rocker-arm.obj",
          ROOT / "bench" / "data" / "stanford-bunny.obj", ROOT / "tests" / "data" / "fandisk.obj")


def row(ao: np.ndarray, covered: np.ndarray, truth, stated) -> dict:
    error = ao[covered] - truth.values[covered]
    magnitude = np.abs(error)
    keep = magnitude < np.quantile(magnitude, 1.0 - TAIL)
    squared = error ** 2

    def rmse(e):
        return float(np.sqrt(max(np.mean(e ** 2) - truth.noise ** 2, 0.0)))
    return {"rmse": rmse(error), "p99": float(np.quantile(magnitude, 0.99)), "bias": float(error.mean()),
            "rmse_without_tail": rmse(error[keep]), "p99_without_tail": float(np.quantile(magnitude[keep], 0.99)),
            "tail_share_of_squared_error": float(squared[~keep].sum() / squared.sum()),
            "stated_rmse": stated.rmse, "stated_p99": stated.p99}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--meshes", nargs="+", default=[str(p) for p in MESHES])
    ap.add_argument("--size", type=int, default=128)
    ap.add_argument("--rays", type=int, default=8192)
    ap.add_argument("--directions", type=int, nargs="+", default=[1024, 4096, 16384])
    ap.add_argument("--view-samples", type=float, nargs="+", default=[2.0, 8.0])
    ap.add_argument("--out", default=str(ROOT / "bench" / "results"))
    args = ap.parse_args()
    from hao_addon.bake import bake
    from hao_addon.blender.gpu_context import ensure_gpu_context
    from hao_addon.core.bake.settings import BakeSettings
    from hao_addon.core.objfile import obj_soup
    ensure_gpu_context()
    rows, truths = [], {}
    for mesh in args.meshes:
        try:
            soup = obj_soup(mesh)
        except ValueError:  # no UVs: unwrapped as a bake unwraps them
            soup = obj_soup(mesh, uvs="auto", size=args.size)
        name = Path(mesh).stem
        start = time.perf_counter()
        truth = texel_truth(soup, [], args.size, rays=args.rays)
        truths[name] = {"texels": int(truth.covered.sum()), "noise_rmse": truth.noise,
                        "seconds": time.perf_counter() - start}
        print(f"truth of {name}: {truths[name]}", flush=True)
        for view_samples in args.view_samples:
            for directions in args.directions:
                settings = BakeSettings(size=args.size, directions=directions, margin=0, normals="face",
                                        method="gather", view_samples=view_samples)
                start = time.perf_counter()
                result = bake(soup, [], settings, use_cache=False)
                rows.append({"mesh": name, "view_samples": view_samples, "directions": directions,
                             "seconds": time.perf_counter() - start,
                             **row(result.ao, result.covered & truth.covered, truth, result.error)})
                print(json.dumps(rows[-1]), flush=True)
    import bpy
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    (out / "floor_bench.json").write_text(json.dumps({
        "size": args.size, "normals": "face", "method": "gather",
        "truth": {"rays": args.rays, "tracer": "Embree (embreex)", "meshes": truths},
        "machine": {"platform": platform.platform(), "python": platform.python_version(),
                    "blender": bpy.app.version_string},
        "rows": rows}, indent=1) + "\n")


if __name__ == "__main__":
    main()
