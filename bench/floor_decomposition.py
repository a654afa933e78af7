# SPDX-License-Identifier: GPL-3.0-or-later
"""What the gather's floor check sees of the floor, texel by texel: the floor probe's values
(each replicate's first probe_half() directions, hao_addon/floor_check.py) and each replicate's
whole value, against the CPU reference's exact rays along the same directions from the same
points, at every covered texel (the bake checks a sample of them).

    .venv/bin/python bench/floor_decomposition.py [--mesh tests/data/rocker-arm.obj]
        [--shading flat] [--directions 4096 16384] [--out bench/results/runs/floor_decomposition.json]

Per direction count: the floor proper's RMS (the part the two replicates share, mean of
floor_a * floor_b) from the probe and from all the directions; the RMS of one replicate's
floor at the probe and at all directions (the part that changes with the rotation is the
difference); the share of the floor's square in its largest 1 and 10 texels; and what
core/bake/error_estimate.with_floor states from every texel's probe floors (the largest
REFINED_SHARE of them taken from all directions, as the bake does) with floor_shape and with
the replicates' mean, beside the p99 of the map minus the exact values.
"""
from __future__ import annotations

import argparse
import json
import sys
from dataclasses import replace
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

import numpy as np  # noqa: E402


def replicate_maps(plan, baker, count: int) -> dict[int, np.ndarray]:
    """{step: (cells,) partial map value} after each replicate's probe and at each one's end."""
    from hao_addon.core.directions import probe_half, replicate_sizes
    from hao_addon.core.bake.probe_snapshot import MapSnapshot
    split, half = replicate_sizes(count)[0], probe_half(count)
    maps = {}
    for i in range(count):
        if i in (half, split, split + half):
            maps[i] = MapSnapshot.of(plan.estimator, baker.accumulated()).values.reshape(-1).astype(np.float64)
            if i == split:
                baker.restart()
        baker.run_direction(i)
    maps[count] = MapSnapshot.of(plan.estimator, baker.accumulated()).values.reshape(-1).astype(np.float64)
    return maps


def exact_map(plan, receivers, steps) -> np.ndarray:
    """(cells,) the CPU reference's value along `steps` from the gather's own points."""
    from hao_addon.core.bake.reference_baker import ReferenceBaker
    from hao_addon.floor_check import START_OFFSET_PIXELS
    baker = ReferenceBaker(plan, receivers, START_OFFSET_PIXELS * plan.pixel_size)
    try:
        for index in steps:
            baker.run_direction(int(index))
        numerator, w = (p.reshape(-1) for p in plan.estimator.ratio(baker.accumulated()))
    finally:
        baker.free()
    return np.divide(numerator, w, out=np.full(w.shape, np.nan), where=w > 0.0)


def decompose(soup, settings, count: int, dump: str = "") -> dict:
    from hao_addon.core.bake import error_estimate as ee
    from hao_addon.core.bake.plan import make_plan_steps
    from hao_addon.core.bake.targets import as_bake_target
    from hao_addon.core.directions import probe_half, replicate_sizes
    from hao_addon.core.steps import drain
    from hao_addon.floor_check import REFINED_SHARE
    from hao_addon.gpu.bake_gather import GatherBaker
    settings = replace(settings, directions=count)
    plan = drain(make_plan_steps(as_bake_target(soup, "image", None, None), [], settings))
    baker = GatherBaker(plan)
    try:
        receivers = baker.sample_receivers(np.arange(settings.size ** 2))
        order = np.asarray(baker.direction_order)
        maps = replicate_maps(plan, baker, count)
    finally:
        baker.free()
    split, half = replicate_sizes(count)[0], probe_half(count)
    parts = {"probe": (order[:half], order[split:split + half], maps[half], maps[split + half]),
             "full": (order[:split], order[split:count], maps[split], maps[count])}
    floors = {}
    for name, (steps_a, steps_b, map_a, map_b) in parts.items():
        floors[name] = (map_a, map_b, exact_map(plan, receivers, steps_a), exact_map(plan, receivers, steps_b))
    seen = np.logical_and.reduce([np.isfinite(v) for vs in floors.values() for v in vs])
    clip = lambda v: np.clip(v[seen], 0.0, 1.0)  # noqa: E731
    fa, fb = {n: clip(v[0]) - clip(v[2]) for n, v in floors.items()}, {n: clip(v[1]) - clip(v[3]) for n, v in floors.items()}
    product = fa["full"] * fb["full"]
    top = np.sort(product)[::-1]
    # the bake's check, at every texel: the largest probe floors again along all directions
    refined = np.zeros(seen.sum(), bool)
    refined[np.argsort(-(fa["probe"] ** 2 + fb["probe"] ** 2), kind="stable")[:int(np.ceil(seen.sum() * REFINED_SHARE))]] = True
    check_a, check_b = np.where(refined, fa["full"], fa["probe"]), np.where(refined, fb["full"], fb["probe"])
    twin = np.zeros(settings.size ** 2)
    twin[seen] = 0.5 * (clip(maps[split]) - clip(maps[count]))
    covered = seen.reshape(settings.size, settings.size)
    twins = ee.estimate(twin.reshape(covered.shape), covered, count)
    sigma = ee.local_rms(twin.reshape(covered.shape), covered).reshape(-1)[seen].astype(np.float64)
    stated = {"floor_shape": ee.with_floor(twins, check_a, check_b, sigma)}
    shape = ee.floor_shape
    try:
        ee.floor_shape = lambda a, b: 0.5 * (a + b)
        stated["replicates_mean"] = ee.with_floor(twins, check_a, check_b, sigma)
    finally:
        ee.floor_shape = shape
    whole = 0.5 * (clip(maps[split]) + clip(maps[count])) - 0.5 * (clip(floors["full"][2]) + clip(floors["full"][3]))
    rms = lambda v: float(np.sqrt(np.mean(v ** 2)))  # noqa: E731
    if dump:  # per-texel arrays, to try other estimates on without baking again
        np.savez_compressed(f"{dump}_{count}.npz", probe_a=fa["probe"], probe_b=fb["probe"], full_a=fa["full"],
                            full_b=fb["full"], refined=refined, sigma=sigma, whole=whole, twins_rmse=twins.rmse,
                            twins_p99=twins.p99)
    return {"directions": count, "probe_directions": half, "texels": int(seen.sum()),
            "floor_proper_probe": float(np.sqrt(max(np.mean(fa["probe"] * fb["probe"]), 0.0))),
            "floor_proper_full": float(np.sqrt(max(np.mean(product), 0.0))),
            "replicate_floor_rms_probe": rms(fa["probe"]), "replicate_floor_rms_full": rms(fa["full"]),
            "top1_share": float(top[0] / top.sum()), "top10_share": float(top[:10].sum() / top.sum()),
            "map_minus_exact_rmse": rms(whole), "map_minus_exact_p99": float(np.percentile(np.abs(whole), 99)),
            "twins_rmse": twins.rmse, "twins_p99": twins.p99,
            "stated": {k: {"rmse": v.rmse, "p99": v.p99, "floor_rmse": v.floor_rmse} for k, v in stated.items()}}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--mesh", default=str(ROOT / "tests" / "data" / "rocker-arm.obj"))
    ap.add_argument("--shading", choices=("flat", "smooth"), default="flat")
    ap.add_argument("--size", type=int, default=128)
    ap.add_argument("--directions", type=int, nargs="+", default=[4096, 16384])
    ap.add_argument("--dump", default="", help="also write each count's per-texel arrays to DUMP_<count>.npz")
    ap.add_argument("--out", default=str(ROOT / "bench" / "results" / "runs" / "floor_decomposition.json"))
    args = ap.parse_args()
    from hao_addon.gpu.context import ensure_gpu_context
    ensure_gpu_context()
    from hao_addon.core.bake.settings import BakeSettings
    from hao_addon.core.geometry import smooth_vertex_normals
    from hao_addon.core.objfile import obj_soup
    try:
        soup = obj_soup(args.mesh)
    except ValueError:  # no UVs: unwrapped as a bake unwraps them
        soup = obj_soup(args.mesh, uvs="auto", size=args.size)
    if args.shading == "smooth":
        soup = replace(soup, normals=smooth_vertex_normals(soup.positions))
    settings = BakeSettings(size=args.size, margin=0, normals="mesh" if args.shading == "smooth" else "face",
                            method="gather", view_samples=2.0)
    rows = []
    for count in args.directions:
        rows.append(decompose(soup, settings, count, args.dump))
        print(json.dumps(rows[-1]), flush=True)
    out = Path(args.out)
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(json.dumps({"mesh": Path(args.mesh).stem, "shading": args.shading, "size": args.size,
                               "rows": rows}, indent=1) + "\n")


if __name__ == "__main__":
    main()
