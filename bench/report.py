# SPDX-License-Identifier: GPL-3.0-or-later
"""Markdown tables from bench/results/bake_bench.json or hao_bench.json (pasted into the README).

    .venv/bin/python bench/report.py [bench/results/bake_bench.json | bench/results/hao_bench.json]

Equal-error speed-up: for each Cycles run, the time HAO needs for the same interior RMSE,
interpolated linearly in log(time)-log(RMSE) between the two HAO runs around it.
"""
from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np


def time_at_rmse(runs: list[dict], rmse: float) -> float | None:
    t = np.log([r["seconds"] for r in runs])
    e = np.log([r["rmse"] for r in runs])
    order = np.argsort(e)
    if not e.min() <= np.log(rmse) <= e.max():
        return None
    return float(np.exp(np.interp(np.log(rmse), e[order], t[order])))


def hao_tables(res: dict) -> str:
    st = res["settings"]
    lines = []
    if "frame" in res:
        lines.append(f"Frame {st['width']}x{st['height']}, AO map 1/{st['scale']}, {st['rays']} rays, {st['grid']}^3 "
                     f"grid, filter {st['filter_size']}, d_max {st['max_distance']}; hierarchical march (budget "
                     f"{st['steps']} steps) and the paper's 8 fixed steps (median ms):\n")
        passes = ("voxelize", "gbuffer", "ao", "low_gbuffer", "filter", "composite")
        lines.append("| scene | triangles | " + " | ".join(passes) + " | frame | Workbench (AA off) | frame / Workbench "
                     "| paper march frame | paper / Workbench |")
        lines.append("|---|---:|" + "---:|" * (len(passes) + 5))
        for name, m in res["frame"].items():
            h = m["hao"]
            lines.append(f"| {name} | {m['triangles']:,} | " + " | ".join(f"{h[p]:.1f}" for p in passes)
                         + f" | {h['frame']:.1f} | {m['workbench_ms']:.1f} | {m['hao_over_workbench']:.2f}x | "
                           f"{m['paper']['frame']:.1f} | {m['paper_over_workbench']:.2f}x |")
        lines.append(f"\nAO passes (sampling + filter), 1M-triangle torus over bunny: {res['ao_passes_1M_over_bunny']:.2f}x.\n")
    if "distances" in res:
        lines.append(f"RMSE against ray-traced truth at {st['points']:,} visible pixels ({st['reference_rays']} rays, "
                     f"same kernel and d_max), HAO (frame ms, cascades) / the paper's march / EEVEE's AO node "
                     f"({st['eevee_samples']} samples):\n")
        factors = [r["factor"] for r in next(iter(res["distances"].values()))["rows"]]
        head = [f"{f:g} x height" if f else "unlimited" for f in factors]
        lines.append("| scene | " + " | ".join(head) + " |")
        lines.append("|---|" + "---|" * len(head))
        for name, m in res["distances"].items():
            cells = [f"**{r['hao']['rmse']:.4f}** ({r['hao']['frame_ms']:.0f}, {r['hao']['cascades']}) / "
                     f"{r['paper']['rmse']:.4f} / {r['eevee']['rmse']:.4f}" for r in m["rows"]]
            lines.append(f"| {name} | " + " | ".join(cells) + " |")
        lines.append("")
    if "character_methods" in res:
        lines.append("Character methods (CesiumMan on the 4-unit floor), RMSE over the visible pixels / on the man:\n")
        methods = ("hao", "far", "near", "near+far", "hao+far")
        lines.append("| frame | d_max | " + " | ".join(methods) + " |")
        lines.append("|---:|---|" + "---|" * len(methods))
        for frame, rows in res["character_methods"].items():
            for d, got in rows.items():
                label = "unlimited" if float(d) == 0.0 else d
                lines.append(f"| {frame} | {label} | " + " | ".join(
                    f"{got['visible'][m]['rmse']:.4f} / {got['man'][m]['rmse']:.4f}" for m in methods) + " |")
        lines.append("")
    for param, rows in res.get("sweeps", {}).items():
        lines.append(f"Sweep of {param} (bunny): " + ", ".join(f"{r['value']}: {r['frame']:.0f} ms" for r in rows) + "\n")
    if res.get("triangles"):
        lines.append("Cost against triangle count (torus on a floor): " + ", ".join(
            f"{r['triangles']:,}: vox {r['voxelize']:.0f} / G-buf {r['gbuffer']:.0f} / AO+filter {r['ao_passes']:.0f} ms"
            for r in res["triangles"]) + "\n")
    m = res["machine"]
    lines.append(f"Machine: {m['platform']}; Blender {m['blender']}; {m['gpu']}.")
    return "\n".join(lines)


def spheres_tables(res: dict) -> str:
    lines = ["Per-frame sphere sync (numpy, object space):\n", "| vertices | K | ms per frame | Lloyd (one-time) |",
             "|---:|---:|---:|---:|"]
    for r in res["sync_numpy"]:
        lines.append(f"| {r['vertices']:,} | {r['k']} | {r['sync_ms']:.2f} | {r['clustering_s']:.1f} s "
                     f"({r['iterations']} it) |")
    sb = res["sync_blender"]
    lines.append(f"\nWhole per-frame path in Blender ({sb['vertices']:,}-vertex armature-deformed mesh, K = {sb['k']}): "
                 f"{sb['per_frame_ms']:.2f} ms when it moved, {sb['unchanged_frame_ms']:.2f} ms when it did not.\n")
    fr = res["frame"]
    lines.append(f"Passes at 800x600 on the walking character: HAO AO sampling (Table 1) {fr['hao_ao_sampling_ms']:.1f} ms; "
                 f"distant spheres ({fr['spheres']:,}) {fr['far_ms']:.1f} ms ({fr['far_over_hao_sampling']:.2f}x); "
                 f"near field (32 samples, both layers) {fr['near_ms']:.1f} ms.\n")
    lines.append("Error against the ray-traced deformed mesh (CesiumMan walk, d_max 0.3), RMSE / frame ms:\n")
    methods = list(next(iter(res["character"].values())))
    lines.append("| frame | " + " | ".join(methods) + " |")
    lines.append("|---:|" + "---:|" * len(methods))
    for frame, rows in res["character"].items():
        lines.append(f"| {frame} | " + " | ".join(f"{rows[m]['rmse']:.4f} / {rows[m]['frame_ms']:.0f}" for m in methods) + " |")
    off = res["offscreen"]
    lines.append("\nFloor in front of a wall behind the camera (d_max 1): " + ", ".join(
        f"{m} RMSE {off[m]['rmse']:.4f} (bias {off[m]['bias']:+.4f})" for m in off) + ".\n")
    lines.append(f"Machine: {res['machine']['platform']}; Blender {res['machine']['blender']}; {res['machine']['gpu']}.")
    return "\n".join(lines)


def main() -> int:
    path = Path(sys.argv[1] if len(sys.argv) > 1 else Path(__file__).parent / "results" / "bake_bench.json")
    print(tables(json.loads(path.read_text())))
    return 0


def tables(res: dict) -> str:
    """Markdown tables of a bake, HAO or spheres benchmark's results."""
    if "sync_numpy" in res:
        return spheres_tables(res)
    if "frame" in res or "distances" in res:
        return hao_tables(res)
    return bake_tables(res)


def bake_tables(res: dict) -> str:
    lines = []
    for name, m in res.get("meshes", {}).items():
        lines.append(f"**{name}** ({m['triangles']:,} triangles, {m['size']}x{m['size']}; xatlas "
                     f"{m['xatlas_seconds']:.1f} s, not included below)\n")
        lines.append("| method | directions / samples | time (s) | RMSE | p99 | bias |")
        lines.append("|---|---:|---:|---:|---:|---:|")
        for key, label in (("scatter", "HAO scatter"), ("gather", "HAO gather"), ("cycles", "Cycles CPU")):
            for r in m["runs"][key]:
                n = r.get("directions", r.get("samples"))
                lines.append(f"| {label} | {n} | {r['seconds']:.2f} | {r['rmse']:.4f} | {r['p99']:.4f} | {r['bias']:+.4f} |")
        lines.append("")
        lines.append("| Cycles samples | Cycles RMSE | Cycles time (s) | HAO scatter, same RMSE | HAO gather, same RMSE |")
        lines.append("|---:|---:|---:|---:|---:|")
        for r in m["runs"]["cycles"]:
            cells = []
            for key in ("scatter", "gather"):
                t = time_at_rmse(m["runs"][key], r["rmse"])
                cells.append("outside measured range" if t is None else f"{t:.2f} s ({r['seconds'] / t:.1f}x faster)")
            lines.append(f"| {r['samples']} | {r['rmse']:.4f} | {r['seconds']:.2f} | {cells[0]} | {cells[1]} |")
        lines.append("")
    for group, label in (("smooth", "shaded smooth"), ("high_to_low", "Selected to Active")):
        for name, m in res.get(group, {}).items():
            methods = [k for k in ("scatter", "gather") if m["runs"].get(k)]
            extra = (f", onto a {m['low_triangles']:,}-triangle Decimate copy" if "low_triangles" in m else "")
            lines.append(f"**{name}, {label}** ({m['triangles']:,} triangles{extra}, {m['size']}x{m['size']}; against "
                         f"Cycles' own bake at {m['truth']['samples']} samples ({m['truth']['seconds']:.0f} s), "
                         f"{m['interior_texels']:,} interior texels)\n")
            lines.append("| method | directions / samples | time (s) | RMSE | p99 | bias |")
            lines.append("|---|---:|---:|---:|---:|---:|")
            for key in (*methods, "cycles"):
                label_m = {"scatter": "HAO scatter", "gather": "HAO gather", "cycles": "Cycles CPU"}[key]
                for r in m["runs"][key]:
                    n = r.get("directions", r.get("samples"))
                    lines.append(f"| {label_m} | {n} | {r['seconds']:.2f} | {r['rmse']:.4f} | {r['p99']:.4f} | "
                                 f"{r['bias']:+.4f} |")
            lines.append("")
            lines.append("| Cycles samples | Cycles RMSE | Cycles time (s) | " +
                         " | ".join(f"HAO {k}, same RMSE" for k in methods) + " |")
            lines.append("|---:|---:|---:|" + "---:|" * len(methods))
            for r in m["runs"]["cycles"]:
                cells = []
                for key in methods:
                    t = time_at_rmse(m["runs"][key], r["rmse"])
                    cells.append("outside measured range" if t is None else f"{t:.2f} s ({r['seconds'] / t:.1f}x faster)")
                lines.append(f"| {r['samples']} | {r['rmse']:.4f} | {r['seconds']:.2f} | " + " | ".join(cells) + " |")
            lines.append("")
    sw = res.get("triangle_sweep")
    if sw:
        lines.append("Cost against triangle count (default method, i.e. the gather at unlimited distance; 1024x1024, 64 directions, UV spheres over a plane):\n")
        lines.append("| triangles | ms per direction |")
        lines.append("|---:|---:|")
        for r in sw:
            lines.append(f"| {r['triangles']:,} | {r['ms_per_direction']:.1f} |")
        lines.append("")
    lines.append(f"Machine: {res['machine']['platform']}; Blender {res['machine']['blender']}; {res['machine']['gpu']}.")
    return "\n".join(lines)


if __name__ == "__main__":
    sys.exit(main())
