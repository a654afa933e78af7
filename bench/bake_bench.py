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
one bake as a user would run it. Both bakers run with margin 0 (no island growth; the error is
measured inside the islands).
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
from hao_addon.core.settings import BakeSettings  # noqa: E402
from hao_addon.core.uv_raster import interior_mask, texel_surface_samples  # noqa: E402
from hao_addon.gpu.context import ensure_gpu_context  # noqa: E402

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


def mesh_object(soup, name):
    pos = soup.positions.reshape(-1, 3)
    verts, inverse = np.unique(pos, axis=0, return_inverse=True)
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata(verts.tolist(), [], inverse.reshape(-1, 3).tolist())
    layer = mesh.uv_layers.new(name="UVMap")
    layer.uv.foreach_set("vector", soup.uvs.reshape(-1).astype(np.float32))
    for p in mesh.polygons:
        p.use_smooth = False  # Cycles then shades with face normals, as HAO does
    obj = bpy.data.objects.new(name, mesh)
    bpy.context.scene.collection.objects.link(obj)
    return obj


def cycles_bake(soup, size, samples_list):
    """Cycles' own AO bake (CPU) of the same UV layout; returns [(samples, seconds, ao)]."""
    bpy.ops.wm.read_factory_settings(use_empty=True)
    obj = mesh_object(soup, "Target")
    img = bpy.data.images.new("cycles_ao", size, size, float_buffer=True)
    img.colorspace_settings.name = 'Non-Color'
    mat = bpy.data.materials.new("bake")
    if mat.node_tree is None:
        mat.use_nodes = True
    tex = mat.node_tree.nodes.new('ShaderNodeTexImage')
    tex.image = img
    mat.node_tree.nodes.active = tex
    obj.data.materials.append(mat)
    scene = bpy.context.scene
    scene.render.engine = 'CYCLES'
    scene.cycles.device = 'CPU'
    scene.cycles.use_denoising = False
    scene.cycles.use_adaptive_sampling = False  # samples mean samples (the default stops near RMSE 0.015)
    scene.world = bpy.data.worlds.new("bench")
    scene.world.light_settings.distance = 1e6  # "unlimited", matching HAO's max distance 0
    bpy.context.view_layer.objects.active = obj
    obj.select_set(True)
    out = []
    # Warm-up (not timed), as for HAO: the first bake of a session pays one-off set-up.
    scene.cycles.samples = 1
    bpy.ops.object.bake(type='AO', use_clear=True, margin=0)
    for spp in samples_list:
        scene.cycles.samples = spp
        t = time.perf_counter()
        bpy.ops.object.bake(type='AO', use_clear=True, margin=0)
        dt = time.perf_counter() - t
        px = np.empty(size * size * 4, np.float32)
        img.pixels.foreach_get(px)
        out.append((spp, dt, px.reshape(size, size, 4)[..., 0].copy()))
        print(f"  cycles {spp:5d} spp: {dt:7.2f} s", flush=True)
    return out


def hao_runs(soup, size, method, directions_list, view_samples=2.0):
    out = []
    # Warm-up (not timed): shader compilation (LLVM JIT, ~0.1 s per variant) happens once per
    # session, and Cycles gets the same courtesy in cycles_bake.
    bake(soup, [], BakeSettings(size=size, directions=8, method=method, view_samples=view_samples, margin=0),
         use_cache=False)
    for d in directions_list:
        t = time.perf_counter()
        # margin=0 as in cycles_bake: neither grows islands (error is measured inside them).
        res = bake(soup, [], BakeSettings(size=size, directions=d, method=method, view_samples=view_samples,
                                          margin=0), use_cache=False)
        dt = time.perf_counter() - t
        out.append((d, dt, res.ao))
        print(f"  {method:7s} {d:5d} dirs: {dt:7.2f} s", flush=True)
    return out


def triangle_sweep(quick):
    """Seconds per direction against triangle count (default method: gather here; 1024^2, 64 directions)."""
    rows = []
    tess = [(32, 16), (64, 32), (128, 64), (256, 128)] if quick else [(32, 16), (64, 32), (128, 64), (256, 128), (512, 256)]
    plane = scenes.grid_plane(8.0, 16)
    for seg, rings in tess:
        sphere = scenes.uv_sphere(1.0, (0, 0, 1.0), seg, rings)
        target = sphere  # the sphere itself is baked: its triangle count drives the cost
        bake(target, [plane], BakeSettings(size=1024, directions=8), use_cache=False)  # warm
        t = time.perf_counter()
        res = bake(target, [plane], BakeSettings(size=1024, directions=64), use_cache=False)
        dt = time.perf_counter() - t
        rows.append(dict(triangles=int(target.face_count + plane.face_count), seconds=dt,
                         ms_per_direction=1000 * dt / 64, view_pixels=res.stats["view_pixels"]))
        print(f"  sweep {rows[-1]['triangles']:7d} tris: {dt:6.2f} s", flush=True)
    return rows


def plot(results, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    names = list(results["meshes"])
    fig, axes = plt.subplots(1, len(names) + 1, figsize=(6 * (len(names) + 1), 4.8))
    styles = {"scatter": ("o-", "HAO scatter (McGraw & Sowers)"), "gather": ("s-", "HAO shadow-map gather"),
              "cycles": ("^-", "Cycles AO bake (CPU)")}
    for ax, name in zip(axes, names):
        m = results["meshes"][name]
        for key, (style, label) in styles.items():
            runs = m["runs"][key]
            ax.loglog([r["seconds"] for r in runs], [r["rmse"] for r in runs], style, label=label)
            for r in runs:
                ax.annotate(str(r.get("directions", r.get("samples"))), (r["seconds"], r["rmse"]), fontsize=7,
                            textcoords="offset points", xytext=(3, 3))
        ax.axhline(0.02, color="gray", lw=0.8, ls="--")
        ax.set_title(f"{name}: {m['triangles']:,} tris, {m['size']}x{m['size']}")
        ax.set_xlabel("wall time (s), 2-core CPU, llvmpipe")
        ax.set_ylabel("interior RMSE vs 1024-ray reference")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=8)
    ax = axes[-1]
    sw = results["triangle_sweep"]
    ax.loglog([r["triangles"] for r in sw], [r["ms_per_direction"] for r in sw], "o-", label="measured")
    t0, c0 = sw[0]["triangles"], sw[0]["ms_per_direction"]
    ax.loglog([r["triangles"] for r in sw], [c0 * r["triangles"] / t0 for r in sw], "k:", label="linear")
    ax.set_xlabel("triangles")
    ax.set_ylabel("ms per direction (1024^2)")
    ax.set_title("cost against triangle count")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=110)


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--quick", action="store_true", help="small sweep (smoke test, minutes)")
    ap.add_argument("--out", default=str(ROOT / "bench" / "results"))
    ap.add_argument("--meshes", default="rocker-arm,bunny")
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
                   settings=dict(size=size, reference_texels=ref_texels, reference_rays=ref_rays, view_samples=2.0),
                   meshes={})
    for name in args.meshes.split(","):
        print(f"{name}:", flush=True)
        t = time.perf_counter()
        soup = obj_soup(MESHES[name], uvs="xatlas", size=size)
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
