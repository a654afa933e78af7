# SPDX-License-Identifier: GPL-3.0-or-later
"""Bake benchmark: run time against error, HAO's two GPU bake variants beside Cycles' CPU AO
bake, in one run on one machine.

    .venv/bin/python bench/bake_bench.py [--quick] [--out bench/results]

Meshes: the rocker arm (McGraw & Sowers' Table 1 row: 20,088 triangles, 1024x1024) and the
Stanford bunny (69,451 triangles), both unwrapped with xatlas. Error is measured over interior
texels (a 2-ring neighbourhood inside one UV chart) against a reference ray traced with 1024
stratified cosine rays per texel at the texel centres: RMSE, 99th percentile of |error| and
bias. Cycles bakes the same UV layout with flat shading and a 1e6 AO distance, so both compute
cosine-weighted, unlimited-distance accessibility on face normals. A triangle-count sweep
(UV spheres, 2k to 500k triangles) checks how cost scales with geometry. Each method bakes
once untimed first (shader compilation; Cycles' first-bake set-up), then every timed run is
one bake as a user would run it; HAO's and Cycles' runs under 30 s alike are repeated three
times and the median kept (tools/timing.py: the machine is shared). Both bakers run with
margin 0 (no island growth; the error is measured inside the islands).
Smooth rows: the same meshes and layouts shaded smooth (Blender's corner normals), HAO and
Cycles at lower sample counts against Cycles' own smooth bake at 1024 samples (all interior
texels). High-to-low row: the bunny baked onto a 2 % Decimate copy of itself (xatlas UVs,
cage extrusion 0.005, max ray distance 0.02), HAO's gather against Cycles' Selected to
Active at 1024 samples. --parts picks the row groups.
Writes bake_bench.json and bake_bench.png into the output folder.
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

import bpy  # noqa: E402
import numpy as np  # noqa: E402

from hao_addon.bake import bake  # noqa: E402
from hao_addon.core import scenes  # noqa: E402
from hao_addon.core.geometry import face_normals_areas  # noqa: E402
from hao_addon.core.objfile import obj_soup  # noqa: E402
from hao_addon.core.reference import build_bvh, reference_accessibility  # noqa: E402
from hao_addon.core.bake.settings import BakeSettings  # noqa: E402
from hao_addon.core.bake.uv_raster import interior_mask, texel_surface_samples  # noqa: E402
from hao_addon.gpu.context import ensure_gpu_context  # noqa: E402
from hao_addon.gpu.bake_gather import VIEWS_PER_DISPATCH  # noqa: E402

sys.path.insert(0, str(ROOT / "tools"))
from cycles_bake import cycles_ao_bake  # noqa: E402
from timing import REPEAT_UNDER_S, REPEATS, median_seconds  # noqa: E402

WARM_UP_DIRECTIONS = VIEWS_PER_DISPATCH
MESHES = {"rocker-arm": ROOT / "tests" / "data" / "rocker-arm.obj",
          "bunny": ROOT / "bench" / "data" / "stanford-bunny.obj"}


def reference_points(soup, size, count, rays, seed=11):
    face, bary, hits = texel_surface_samples(soup.uvs, size)
    inner = interior_mask(face, hits)
    rng = np.random.default_rng(seed)
    ys, xs = np.nonzero(inner)
    pick = rng.choice(len(ys), min(count, len(ys)), replace=False)
    ys, xs = ys[pick], xs[pick]
    f = face[ys, xs]
    pts = np.einsum("nk,nkd->nd", bary[ys, xs], soup.positions[f])
    normals, _ = face_normals_areas(soup.positions)
    t = time.perf_counter()
    ref = reference_accessibility(pts, normals[f], soup.positions, rays=rays, seed=seed, bvh=build_bvh(soup.positions))
    return ys, xs, ref, time.perf_counter() - t, int(inner.sum())


def errors(ao, ys, xs, ref):
    e = ao[ys, xs].astype(np.float64) - ref
    return dict(rmse=float(np.sqrt((e * e).mean())), p99=float(np.percentile(np.abs(e), 99)), bias=float(e.mean()))


def mesh_object(soup, name, smooth: bool = False, uvs: bool = True):
    pos = soup.positions.reshape(-1, 3)
    verts, inverse = np.unique(pos, axis=0, return_inverse=True)
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata(verts.tolist(), [], inverse.reshape(-1, 3).tolist())
    if uvs:
        layer = mesh.uv_layers.new(name="UVMap")
        layer.uv.foreach_set("vector", soup.uvs.reshape(-1).astype(np.float32))
    for p in mesh.polygons:
        p.use_smooth = smooth  # flat: Cycles then shades with face normals, as HAO's flat rows do
    obj = bpy.data.objects.new(name, mesh)
    bpy.context.scene.collection.objects.link(obj)
    return obj


def cycles_bake(soup, size, samples_list):
    """Cycles' own AO bake (CPU, flat shading) of the same UV layout; returns [(samples, seconds, ao)]."""
    bpy.ops.wm.read_factory_settings(use_empty=True)
    obj = mesh_object(soup, "Target")
    # Warm-up (not timed), as for HAO: the first bake of a session pays one-off set-up.
    return cycles_ao_bake(obj, size, samples_list, warm_up=True, log=True, repeat_under_s=REPEAT_UNDER_S)


def hao_runs(soup, size, method, directions_list, view_samples=2.0, high_to_low=None, **settings):
    out = []
    # Warm-up (not timed): shader compilation (LLVM JIT, ~0.1 s per variant) happens once per
    # session, and Cycles gets the same courtesy in cycles_bake. WARM_UP_DIRECTIONS fill the
    # gather's largest batch, so the timed bakes use the variant compiled here.
    bake(soup, [], BakeSettings(size=size, directions=WARM_UP_DIRECTIONS, method=method, view_samples=view_samples,
                                margin=0, **settings), use_cache=False, high_to_low=high_to_low)
    for d in directions_list:
        # margin=0 as in cycles_bake: neither grows islands (error is measured inside them).
        dt, res = median_seconds(lambda d=d: bake(
            soup, [], BakeSettings(size=size, directions=d, method=method, view_samples=view_samples, margin=0,
                                   **settings), use_cache=False, high_to_low=high_to_low))
        out.append((d, dt, res.ao))
        print(f"  {method:7s} {d:5d} dirs: {dt:7.2f} s", flush=True)
    return out


def truth_errors(ao, truth, mask):
    """RMSE, p99 and bias of ao against a Cycles truth over the mask (2-ring interior texels
    both bakes cover)."""
    e = ao[mask].astype(np.float64) - truth[mask]
    return dict(rmse=float(np.sqrt((e * e).mean())), p99=float(np.percentile(np.abs(e), 99)), bias=float(e.mean()))


def smooth_rows(soup, size, dirs, spp, truth_spp):
    """The mesh shaded smooth (Blender's corner normals), HAO's two bakers and Cycles at lower
    sample counts (seed 1) against Cycles' smooth bake at truth_spp (seed 0)."""
    from hao_addon.blender import mesh_data

    bpy.ops.wm.read_factory_settings(use_empty=True)
    obj = mesh_object(soup, "Smooth", smooth=True)
    smooth = mesh_data.evaluated_soup(obj, bpy.context.evaluated_depsgraph_get(), "UVMap")
    (_, truth_s, truth), = cycles_ao_bake(obj, size, [truth_spp], seed=0, warm_up=True, log=True)
    face, _bary, hits = texel_surface_samples(soup.uvs, size)
    mask = interior_mask(face, hits) & (truth > 0)
    runs = {"scatter": [], "gather": [], "cycles": []}
    for s, dt, ao in cycles_ao_bake(obj, size, spp, seed=1, log=True, repeat_under_s=REPEAT_UNDER_S):
        runs["cycles"].append(dict(samples=s, seconds=dt, **truth_errors(ao, truth, mask)))
    for method in ("scatter", "gather"):
        for d, dt, ao in hao_runs(smooth, size, method, dirs):
            runs[method].append(dict(directions=d, seconds=dt, **truth_errors(ao, truth, mask)))
    return dict(triangles=soup.face_count, size=size, truth=dict(samples=truth_spp, seconds=truth_s),
                smooth_corners=int((np.abs(smooth.normals - face_normals_areas(smooth.positions)[0][:, None]).sum(-1)
                                    > 1e-6).sum()), interior_texels=int(mask.sum()), runs=runs)


# The high-to-low pair: the bunny onto a 2 % Decimate copy, unwrapped by xatlas, both shaded
# smooth (as tests/shading_scenes.HIGH_TO_LOW, at the benchmark's size).
PAIR_RATIO, PAIR_EXTRUSION, PAIR_MAX_RAY = 0.02, 0.005, 0.02


def high_to_low_rows(size, dirs, spp, truth_spp):
    """Selected to Active of the bunny pair: HAO's gather (the scatter cannot bake it) and
    Cycles at lower sample counts (seed 1) against Cycles' Selected-to-Active bake at truth_spp."""
    from hao_addon.bake import HighToLow
    from hao_addon.blender import mesh_data
    from hao_addon.core.objfile import read_obj
    from hao_addon.core.bake.unwrap import xatlas_unwrap

    bpy.ops.wm.read_factory_settings(use_empty=True)
    v, t, _uv, _tu = read_obj(MESHES["bunny"])
    high = mesh_object(_soup(v, t), "High", smooth=True, uvs=False)
    modifier = high.modifiers.new("decimate", 'DECIMATE')
    modifier.ratio = PAIR_RATIO
    dg = bpy.context.evaluated_depsgraph_get()
    low_mesh = high.evaluated_get(dg).to_mesh()
    low_mesh.calc_loop_triangles()
    lv = np.array([x.co[:] for x in low_mesh.vertices])
    lt = np.array([tri.vertices[:] for tri in low_mesh.loop_triangles])
    high.modifiers.remove(modifier)
    t0 = time.perf_counter()
    low_soup = _soup(lv, lt, xatlas_unwrap(lv, lt, size))
    unwrap_s = time.perf_counter() - t0
    low = mesh_object(low_soup, "Low", smooth=True)
    dg = bpy.context.evaluated_depsgraph_get()
    target = mesh_data.evaluated_soup(low, dg, "UVMap")
    source = mesh_data.evaluated_soup(high, dg, None)
    normals, linear = mesh_data.extrusion_normals(low, dg)
    request = HighToLow([source], normals, low_linear=linear)
    (_, truth_s, truth), = cycles_ao_bake(low, size, [truth_spp], seed=0, sources=(high,),
                                          cage_extrusion=PAIR_EXTRUSION, max_ray_distance=PAIR_MAX_RAY,
                                          warm_up=True, log=True)
    face, _bary, hits = texel_surface_samples(low_soup.uvs, size)
    runs = {"gather": [], "cycles": []}
    for s, dt, ao in cycles_ao_bake(low, size, spp, seed=1, sources=(high,), cage_extrusion=PAIR_EXTRUSION,
                                    max_ray_distance=PAIR_MAX_RAY, log=True, repeat_under_s=REPEAT_UNDER_S):
        runs["cycles"].append(dict(samples=s, seconds=dt, ao=ao))
    gather = hao_runs(target, size, "gather", dirs, high_to_low=request, cage_extrusion=PAIR_EXTRUSION,
                      max_ray_distance=PAIR_MAX_RAY)
    mask = interior_mask(face, hits) & (truth > 0) & (gather[-1][2] > 0)  # texels both bakes found
    for r in runs["cycles"]:
        r.update(truth_errors(r.pop("ao"), truth, mask))
    for d, dt, ao in gather:
        runs["gather"].append(dict(directions=d, seconds=dt, **truth_errors(ao, truth, mask)))
    return dict(triangles=int(len(t)), low_triangles=int(len(lt)), size=size, xatlas_seconds=unwrap_s,
                truth=dict(samples=truth_spp, seconds=truth_s), interior_texels=int(mask.sum()), runs=runs)


def _soup(v, t, uvs=None):
    from hao_addon.core.geometry import TriangleSoup
    return TriangleSoup(np.asarray(v, np.float64)[t], uvs)


def triangle_sweep(quick):
    """Seconds per direction against triangle count (default method: gather here; 1024^2, 64 directions)."""
    rows = []
    tess = [(32, 16), (64, 32), (128, 64), (256, 128)] if quick else [(32, 16), (64, 32), (128, 64), (256, 128), (512, 256)]
    plane = scenes.grid_plane(8.0, 16)
    for seg, rings in tess:
        sphere = scenes.uv_sphere(1.0, (0, 0, 1.0), seg, rings)
        target = sphere  # the sphere itself is baked: its triangle count drives the cost
        bake(target, [plane], BakeSettings(size=1024, directions=WARM_UP_DIRECTIONS), use_cache=False)  # warm
        t = time.perf_counter()
        res = bake(target, [plane], BakeSettings(size=1024, directions=64), use_cache=False)
        dt = time.perf_counter() - t
        rows.append(dict(triangles=int(target.face_count + plane.face_count), seconds=dt,
                         ms_per_direction=1000 * dt / 64, view_pixels=res.stats["view_pixels"]))
        print(f"  sweep {rows[-1]['triangles']:7d} tris: {dt:6.2f} s", flush=True)
    return rows


def plot(results, path):
    """One time-against-error panel per row group and mesh (flat against the ray-traced
    reference, smooth and high-to-low against Cycles' own bake at high samples), plus the
    triangle sweep."""
    from plot_grid import panel_grid, save
    panels = [(f"{name} (flat)", m, "interior RMSE vs 1024-ray reference")
              for name, m in results.get("meshes", {}).items()]
    for group, label in (("smooth", "smooth"), ("high_to_low", "Selected to Active")):
        for name, m in results.get(group, {}).items():
            panels.append((f"{name} ({label})", m, f"interior RMSE vs Cycles {m['truth']['samples']} spp"))
    sweep = results.get("triangle_sweep")
    fig, axes = panel_grid(len(panels) + (1 if sweep else 0))
    styles = {"scatter": ("o-", "C0", "HAO scatter (McGraw & Sowers)"), "gather": ("s-", "C1", "HAO shadow-map gather"),
              "cycles": ("^-", "C2", "Cycles AO bake (CPU)")}
    for ax, (title, m, ylabel) in zip(axes, panels):
        for key, (style, color, label) in styles.items():
            runs = m["runs"].get(key)
            if not runs:
                continue
            ax.loglog([r["seconds"] for r in runs], [r["rmse"] for r in runs], style, color=color, label=label)
            for r in runs:
                ax.annotate(str(r.get("directions", r.get("samples"))), (r["seconds"], r["rmse"]), fontsize=7,
                            textcoords="offset points", xytext=(3, 3))
        ax.axhline(0.02, color="gray", lw=0.8, ls="--")
        ax.set_title(f"{title}: {m['triangles']:,} tris, {m['size']}x{m['size']}")
        ax.set_xlabel("wall time (s), 2-core CPU, llvmpipe")
        ax.set_ylabel(ylabel)
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=8)
    if sweep:
        ax = axes[len(panels)]
        ax.loglog([r["triangles"] for r in sweep], [r["ms_per_direction"] for r in sweep], "o-", label="measured")
        t0, c0 = sweep[0]["triangles"], sweep[0]["ms_per_direction"]
        ax.loglog([r["triangles"] for r in sweep], [c0 * r["triangles"] / t0 for r in sweep], "k:", label="linear")
        ax.set_xlabel("triangles")
        ax.set_ylabel("ms per direction (1024^2)")
        ax.set_title("cost against triangle count")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=8)
    save(fig, path)


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--quick", action="store_true", help="small sweep (smoke test, minutes)")
    ap.add_argument("--out", default=str(ROOT / "bench" / "results"))
    ap.add_argument("--meshes", default="rocker-arm,bunny")
    ap.add_argument("--parts", default="flat,smooth,high-to-low", help="row groups to run (comma-separated)")
    args = ap.parse_args()
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    ensure_gpu_context()
    size = 512 if args.quick else 1024
    dirs = [64, 256] if args.quick else [64, 128, 256, 512, 1024]
    spp = [16, 64] if args.quick else [16, 64, 256, 1024]
    ref_texels, ref_rays = (500, 256) if args.quick else (2000, 1024)
    results = dict(machine=dict(platform=platform.platform(), processor=platform.processor(),
                                blender=bpy.app.version_string, gpu=_gpu_name()),
                   settings=dict(size=size, reference_texels=ref_texels, reference_rays=ref_rays, view_samples=2.0,
                                 timing_repeats=REPEATS, repeat_under_s=REPEAT_UNDER_S),
                   meshes={})
    parts = args.parts.split(",")
    truth_spp = 256 if args.quick else 1024
    for name in args.meshes.split(",") if "flat" in parts else []:
        print(f"{name}:", flush=True)
        t = time.perf_counter()
        soup = obj_soup(MESHES[name], uvs="auto", size=size)
        unwrap_s = time.perf_counter() - t
        ys, xs, ref, ref_s, interior = reference_points(soup, size, ref_texels, ref_rays)
        print(f"  reference: {len(ref)} texels x {ref_rays} rays in {ref_s:.1f} s", flush=True)
        runs = {"scatter": [], "gather": [], "cycles": []}
        for method in ("scatter", "gather"):
            for d, dt, ao in hao_runs(soup, size, method, dirs):
                runs[method].append(dict(directions=d, seconds=dt, **errors(ao, ys, xs, ref)))
        for s, dt, ao in cycles_bake(soup, size, spp):
            runs["cycles"].append(dict(samples=s, seconds=dt, **errors(ao, ys, xs, ref)))
        results["meshes"][name] = dict(triangles=soup.face_count, size=size, xatlas_seconds=unwrap_s,
                                       reference_seconds=ref_s, interior_texels=interior, runs=runs)
        (out / "bake_bench.json").write_text(json.dumps(results, indent=1))
    for name in args.meshes.split(",") if "smooth" in parts else []:
        print(f"{name}, shaded smooth:", flush=True)
        soup = obj_soup(MESHES[name], uvs="auto", size=size)
        results.setdefault("smooth", {})[name] = smooth_rows(soup, size, dirs, spp[:-1] or spp, truth_spp)
        (out / "bake_bench.json").write_text(json.dumps(results, indent=1))
    if "high-to-low" in parts:
        print("bunny pair, Selected to Active:", flush=True)
        results["high_to_low"] = {"bunny": high_to_low_rows(size, dirs, spp[:-1] or spp, truth_spp)}
        (out / "bake_bench.json").write_text(json.dumps(results, indent=1))
    if "flat" in parts:
        print("triangle sweep:", flush=True)
        results["triangle_sweep"] = triangle_sweep(args.quick)
    (out / "bake_bench.json").write_text(json.dumps(results, indent=1))
    plot(results, out / "bake_bench.png")
    print(f"wrote {out / 'bake_bench.json'} and {out / 'bake_bench.png'}")
    return 0


def _gpu_name() -> str:
    import gpu
    try:
        return f"{gpu.platform.vendor_get()} {gpu.platform.renderer_get()}"
    except Exception:  # noqa: BLE001 - informative only
        return "unknown"


if __name__ == "__main__":
    sys.exit(main())
