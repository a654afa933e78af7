# SPDX-License-Identifier: GPL-3.0-or-later
"""Error benchmark: does a bake's own error estimate match the measured error, what does the
estimate cost, and what does baking to a stated error cost against the fixed direction count
that reaches the same error, in one run on one machine.

    .venv/bin/python bench/error_bench.py [--out bench/results] [--quick]

Meshes: the smooth rocker arm and smooth Spot at 256^2 in the layouts of Cycles' truths
(tests/data/cycles_*.npz), and the smooth Stanford bunny (69,451 triangles, xatlas UVs; no
Cycles truth, so its calibration is against the converged map alone), baked by the gather
(Auto's method for them).
- Calibration: estimated RMSE and p99 at 64, 256 and 1024 directions beside the measured ones:
  against Cycles (two seeds of 1024 samples, their noise taken out of the RMSE) and against our
  converged map (two gather seeds of CONVERGED directions, their noise taken out).
- Cost: the bake at 256 directions with its two replicates summed apart against the same bake
  as one set (the estimate switched off), medians of interleaved runs.
- To an error: --max-error at half an 8-bit step (p99 1/510) as shipped, and with its rounds
  leaving converged texels out (SKIP_CONVERGED, off as shipped), against fixed counts; each's measured p99
  against the converged map, and the smallest fixed count that reaches it. The converged map's
  own noise is of the order of that target, so measured p99s are given raw and with the
  truth's noise p99 taken out in quadrature (exact for normal errors).
Writes error_bench.json and error_bench.png into the output folder.
"""
from __future__ import annotations

import argparse
import contextlib
import json
import platform
import statistics
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path[:0] = [str(ROOT), str(ROOT / "tests")]

import bpy  # noqa: E402, F401 - Blender first: its gpu module needs bpy loaded
import numpy as np  # noqa: E402

import shading_scenes as cases  # noqa: E402
import hao_addon.bake as bake_module  # noqa: E402
import hao_addon.core.directions as directions_module  # noqa: E402
from hao_addon.bake import bake  # noqa: E402
from hao_addon.gpu.context import ensure_gpu_context  # noqa: E402
from hao_addon.core.bake.settings import BakeSettings  # noqa: E402

MESHES = ["rocker_smooth", "spot_smooth", "bunny_smooth"]
BUNNY = ROOT / "bench" / "data" / "stanford-bunny.obj"
TARGET = 0.5 / 255.0


def load(name):
    """(soup, Cycles' mean or None, its noise variance or None, interior texels)."""
    if name != "bunny_smooth":
        return cases.evaluated_case(name)
    from hao_addon.core.bake.uv_raster import interior_mask, texel_surface_samples
    from hao_addon.core.geometry import TriangleSoup, smooth_vertex_normals
    from hao_addon.core.objfile import obj_soup
    soup = obj_soup(BUNNY, uvs="auto", size=cases.TRUTH_SIZE)
    soup = TriangleSoup(soup.positions, soup.uvs, "bunny", smooth_vertex_normals(soup.positions))
    face, _b, hits = texel_surface_samples(soup.uvs, cases.TRUTH_SIZE)
    return soup, None, None, interior_mask(face, hits)


def gather(soup, name, directions, seed=0, **kw):
    t = time.perf_counter()
    res = bake(soup, [], BakeSettings(size=cases.TRUTH_SIZE, directions=directions, method="gather", margin=0, seed=seed,
                                      terminator_offset=cases.terminator_offset(name), **kw), use_cache=False)
    return time.perf_counter() - t, res


def measured(ao, truth, var, mask):
    e = ao[mask].astype(np.float64) - truth[mask]
    p99 = float(np.percentile(np.abs(e), 99))
    noise_p99 = float(np.percentile(np.sqrt(var[mask]), 99))  # |a - b| / 2: a draw of the truth's noise
    return dict(rmse=float(np.sqrt(max((e * e).mean() - var[mask].mean(), 0.0))), p99=p99,
                p99_noise_out=float(np.sqrt(max(p99 ** 2 - noise_p99 ** 2, 0.0))))


class Skipping:
    """Bakes to an error whose rounds after the first leave converged texels out (off as
    shipped: hao_addon.bake.SKIP_CONVERGED)."""

    def __enter__(self):
        bake_module.SKIP_CONVERGED = True
        return self

    def __exit__(self, *exc):
        bake_module.SKIP_CONVERGED = False


class OneSet:
    """The bake without its error estimate: one rotated Fibonacci set, summed at once."""

    def __enter__(self):
        self.saved = directions_module.REPLICATES
        directions_module.REPLICATES = 1
        return self

    def __exit__(self, *exc):
        directions_module.REPLICATES = self.saved


def cost_of_estimate(soup, name, repeats):
    with_t, without_t = [], []
    for _ in range(repeats):
        with_t.append(gather(soup, name, 256)[0])
        with OneSet():
            without_t.append(gather(soup, name, 256)[0])
    return dict(with_estimate_s=statistics.median(with_t), one_set_s=statistics.median(without_t),
                ratio=statistics.median(with_t) / statistics.median(without_t))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--out", default=str(ROOT / "bench" / "results"))
    ap.add_argument("--quick", action="store_true")
    args = ap.parse_args()
    out_dir = Path(args.out)
    out_dir.mkdir(parents=True, exist_ok=True)
    ensure_gpu_context()
    converged_count = 4096 if args.quick else 32768
    fixed_counts = [1024, 2048, 4096] if args.quick else [1024, 2048, 4096, 8192, 16384]
    results = dict(machine=platform.platform(), target_p99=TARGET, converged_directions=converged_count, meshes={})
    for name in MESHES:
        soup, cycles, cycles_var, inner = load(name)
        gather(soup, name, 64)  # warm-up: shader variants
        high = [gather(soup, name, converged_count, seed=s)[1] for s in (101, 102)]
        converged = 0.5 * (high[0].ao.astype(np.float64) + high[1].ao)
        converged_var = (high[0].ao.astype(np.float64) - high[1].ao) ** 2 / 4.0
        row = dict(calibration=[], fixed=[], cost=cost_of_estimate(soup, name, 3 if args.quick else 5))
        for d in (64, 256, 1024):
            seconds, res = gather(soup, name, d)
            mask = inner & res.covered & high[0].covered
            est = bake_module.estimate(res.twin, mask, d)
            row["calibration"].append(dict(directions=d, seconds=seconds, estimated=est.as_dict(),
                                           vs_cycles=None if cycles is None else measured(res.ao, cycles, cycles_var,
                                                                                          mask),
                                           vs_converged=measured(res.ao, converged, converged_var, mask)))
            print(f"{name} {d:5d}: est {est.rmse:.5f}/{est.p99:.4f}  Cycles {row['calibration'][-1]['vs_cycles']} "
                  f"converged {row['calibration'][-1]['vs_converged']}", flush=True)
        for d in fixed_counts:
            seconds, res = gather(soup, name, d)
            mask = inner & res.covered & high[0].covered
            row["fixed"].append(dict(directions=d, seconds=seconds, estimated=res.error.as_dict(),
                                     vs_converged=measured(res.ao, converged, converged_var, mask)))
            print(f"{name} fixed {d:5d}: {seconds:6.2f} s, p99 measured {row['fixed'][-1]['vs_converged']} "
                  f"estimated {res.error.p99:.5f}", flush=True)
        for key, context in (("to_error", contextlib.nullcontext()), ("to_error_skipping", Skipping())):
            with context:
                seconds, res = gather(soup, name, fixed_counts[-1] * 2, max_error=TARGET)
            mask = inner & res.covered & high[0].covered
            row[key] = dict(seconds=seconds, rounds=res.stats["rounds"], estimated=res.error.as_dict(),
                            vs_converged=measured(res.ao, converged, converged_var, mask),
                            skipped_fraction=res.stats["skippable_fraction"])
            print(f"{name} {key} p99 {TARGET:.5f}: {seconds:.2f} s, rounds {res.stats['rounds']}, measured "
                  f"{row[key]['vs_converged']}, estimated {res.error.p99:.5f}, skipped "
                  f"{res.stats['skippable_fraction']:.2f}", flush=True)
        reaching = [f for f in row["fixed"] if f["vs_converged"]["p99_noise_out"] <= TARGET]
        row["smallest_fixed_reaching"] = reaching[0]["directions"] if reaching else None
        if reaching:
            row["speedup_vs_smallest_fixed"] = reaching[0]["seconds"] / row["to_error"]["seconds"]
        row["speedup_from_skipping"] = row["to_error"]["seconds"] / row["to_error_skipping"]["seconds"]
        print(f"{name}: smallest fixed count reaching it {row['smallest_fixed_reaching']}, "
              f"speed-up {row.get('speedup_vs_smallest_fixed')}, from skipping {row['speedup_from_skipping']:.2f}",
              flush=True)
        results["meshes"][name] = row
    (out_dir / "error_bench.json").write_text(json.dumps(results, indent=1))
    plot(results, out_dir / "error_bench.png")


def plot(results, path):
    from plot_grid import panel_grid, save
    fig, axes = panel_grid(len(results["meshes"]))
    for ax, (name, row) in zip(axes, results["meshes"].items()):
        for key, style in (("calibration", "o"), ("fixed", "s")):
            t = [r["seconds"] for r in row[key]]
            ax.loglog(t, [r["estimated"]["p99"] for r in row[key]], style + "-", label=f"{key}: estimated p99")
            ax.loglog(t, [r["vs_converged"]["p99_noise_out"] for r in row[key]], style + "--",
                      label=f"{key}: measured p99 (truth noise out)")
        te = row["to_error"]
        ax.loglog([te["seconds"]], [te["vs_converged"]["p99_noise_out"]], "r*", ms=14,
                  label="--max-error 1/510: measured (truth noise out)")
        ax.loglog([te["seconds"]], [te["estimated"]["p99"]], "k+", ms=14, label="--max-error 1/510: estimated")
        ax.axhline(results["target_p99"], color="grey", lw=0.8)
        ax.set_title(name)
        ax.set_xlabel("bake seconds (gather, 256^2)")
        ax.set_ylabel("p99 |error|")
        ax.legend(fontsize=7)
    save(fig, path)


if __name__ == "__main__":
    main()
