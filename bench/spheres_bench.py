# SPDX-License-Identifier: GPL-3.0-or-later
"""Sphere-proxy benchmark (Shanmugam & Arikan methods beside HAO), one run on one machine.

    .venv/bin/python bench/spheres_bench.py [--quick] [--out bench/results]

1. Sync: per-frame sphere update (numpy bincounts over the deformed vertices) against vertex
   count (10k to 1M) and K; and the whole per-frame path in Blender (evaluated mesh read,
   change check, update) for an armature-deformed mesh of 100k vertices.
2. Frame: per-pass times at 800x600: the distant-sphere pass with 1,000 spheres (2-6 cm,
   spread over the character's volume) against HAO's AO-sampling pass at Table 1 settings
   on the same frame (the walking CesiumMan), and the near-field pass (32 samples).
3. Error: every method (hao, near, far, near+far, hao+far) against a ray-traced reference
   (512 rays, Wendland kernel, d_max 0.3) on the walking CesiumMan over a floor (three
   frames), and hao against near on a floor darkened by a wall behind the camera (d_max 1;
   the paper's figure 9, HAO against screen space, as numbers).
Writes spheres_bench.json and spheres_bench.png.
"""
from __future__ import annotations

import argparse
import json
import platform
import statistics
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

import bpy  # noqa: E402
import gpu  # noqa: E402
import numpy as np  # noqa: E402

from hao_addon.core.hao import camera_math as cm  # noqa: E402
from hao_addon.core import scenes  # noqa: E402
from hao_addon.core.proxies.lloyd import lloyd_clusters, sphere_proxies, vertex_areas  # noqa: E402
from hao_addon.core.reference import build_bvh, reference_accessibility  # noqa: E402
from hao_addon.core.hao.view_scene import object_from_soup  # noqa: E402
from hao_addon.core.hao.view_settings import ViewAOSettings  # noqa: E402
from hao_addon.gpu.context import ensure_gpu_context  # noqa: E402

WIDTH, HEIGHT = 800, 600
METHODS = ("hao", "near", "far", "near+far", "hao+far")


def torus_mesh(vertices: int):
    sides = max(8, int(np.sqrt(vertices / 2)))
    seg = max(8, vertices // sides)
    soup = scenes.torus(0.3, 0.1, (0, 0, 0.1), seg, sides)
    pos = soup.positions.reshape(-1, 3)
    verts, inverse = np.unique(pos, axis=0, return_inverse=True)
    return verts, inverse.reshape(-1, 3)


def timeit(fn, repeats):
    times = []
    for _ in range(repeats):
        t = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t)
    return 1000 * statistics.median(times)


def sync_numpy(quick):
    rows = []
    for nv in ((10_000, 100_000) if quick else (10_000, 100_000, 1_000_000)):
        verts, tris = torus_mesh(nv)
        w = vertex_areas(verts, tris)
        for k in (8, 128, 1024):
            t = time.perf_counter()
            cl = lloyd_clusters(verts, w, k, max_iterations=20 if nv > 100_000 else 100)
            cluster_s = time.perf_counter() - t
            moved = verts * 1.01
            ms = timeit(lambda moved=moved, cl=cl, w=w, k=k: sphere_proxies(moved, cl.labels, w, k), 9)
            rows.append(dict(vertices=len(verts), k=k, sync_ms=ms, clustering_s=cluster_s, iterations=cl.iterations))
            print(f"  sync numpy {len(verts):8,d} verts K={k:5d}: {ms:6.2f} ms/frame "
                  f"(Lloyd {cluster_s:.2f} s, {cl.iterations} it)", flush=True)
    return rows


def sync_blender(k=128):
    """A 100k-vertex mesh deformed by an animated armature: the whole per-frame path."""
    from hao_addon.blender import sphere_proxies as sp
    bpy.ops.wm.read_factory_settings(use_empty=True)
    bpy.ops.mesh.primitive_uv_sphere_add(segments=400, ring_count=250, radius=0.5)
    body = bpy.context.active_object
    bpy.ops.object.armature_add(location=(0, 0, 0))
    arm = bpy.context.active_object
    mod = body.modifiers.new("arm", 'ARMATURE')
    mod.object = arm
    group = body.vertex_groups.new(name=arm.data.bones[0].name)
    group.add(list(range(len(body.data.vertices))), 1.0, 'REPLACE')
    arm.pose.bones[0].rotation_mode = 'XYZ'
    for f, angle in ((1, 0.0), (48, 1.0)):
        arm.pose.bones[0].rotation_euler = (angle, 0.0, 0.0)
        arm.pose.bones[0].keyframe_insert("rotation_euler", frame=f)
    sp.make_proxies(body, k)
    times = []
    for frame in range(2, 40):
        bpy.context.scene.frame_set(frame)
        dg = bpy.context.evaluated_depsgraph_get()
        t = time.perf_counter()
        sp.object_spheres(body, dg)
        times.append(time.perf_counter() - t)
    t = time.perf_counter()
    sp.object_spheres(body, bpy.context.evaluated_depsgraph_get())  # unchanged: reuse
    reuse_ms = 1000 * (time.perf_counter() - t)
    out = dict(vertices=len(body.data.vertices), k=k, per_frame_ms=1000 * statistics.median(times),
               unchanged_frame_ms=reuse_ms)
    print(f"  sync in Blender {out['vertices']:,} verts K={k}: {out['per_frame_ms']:.2f} ms/frame "
          f"(unchanged: {reuse_ms:.2f} ms)", flush=True)
    return out


def finish(tex):
    tex.read()


def frame_passes(renderer, objects, vp, spheres, repeats):
    """Time HAO's AO sampling and the far pass with the given spheres on one frame (ms)."""
    table1 = ViewAOSettings(rays=32, steps=8, grid=256, scale=2, filter_size=16, max_distance=0.3)
    renderer.invalidate()
    renderer.render(objects, vp, WIDTH, HEIGHT, table1)

    def ao():
        renderer.sampling.run(renderer.gbuffer, renderer.voxels, table1)
        finish(renderer.sampling.ao_low)

    def far():  # the once-per-view low-resolution G-buffer included
        renderer.sampling.clear(renderer.gbuffer, 2)
        renderer.low_gbuffer.run(renderer.gbuffer, 2)
        renderer.far.run(renderer.low_gbuffer, renderer.sampling.ao_low, spheres[0], spheres[1], 0.05, vp)
        finish(renderer.sampling.ao_low)

    def near():
        from hao_addon.gpu.near_field import run_near_field
        renderer.back.render(vp, WIDTH, HEIGHT)
        run_near_field(renderer.gbuffer, renderer.back, renderer.sampling.ao_low, 2, vp, 0.3, 32)
        finish(renderer.sampling.ao_low)

    ao()
    far()
    near()
    return dict(hao_ao_sampling_ms=timeit(ao, repeats), far_ms=timeit(far, repeats), near_ms=timeit(near, repeats),
                spheres=len(spheres[1]))


def character_scene(frame, k):
    """The walking CesiumMan on a 4-unit floor with K sphere proxies (hao_bench.character_objects)."""
    from hao_bench import character_objects
    return character_objects(frame, 4.0, k)


def method_errors(renderer, objects, spheres, vp, methods, points, rays, seed, receivers=None, max_distance=0.3):
    rows = {}
    settings0 = ViewAOSettings(max_distance=max_distance, grid=256)
    renderer.invalidate()
    renderer.render(objects, vp, WIDTH, HEIGHT, settings0.with_(method="hao"))
    pos, nrm, _ = renderer.gbuffer.read()
    mask = pos[..., 3] >= 1.0
    if receivers is not None:
        mask &= receivers(pos)
    ys, xs = np.nonzero(mask)
    rng = np.random.default_rng(seed)
    pick = rng.choice(len(ys), min(points, len(ys)), replace=False)
    ys, xs = ys[pick], xs[pick]
    tris = np.concatenate([o.world_positions() for o in objects])
    ref = reference_accessibility(pos[ys, xs, :3].astype(np.float64), nrm[ys, xs, :3].astype(np.float64), tris,
                                  rays=rays, max_distance=max_distance, falloff="wendland", seed=seed,
                                  bvh=build_bvh(tris))
    for method in methods:
        s = settings0.with_(method=method)
        renderer.invalidate()
        renderer.render(objects, vp, WIDTH, HEIGHT, s, spheres=spheres)  # warm (uploads)
        times = []
        for _ in range(3):
            renderer.invalidate(keep=("upload",))
            t = time.perf_counter()
            renderer.render(objects, vp, WIDTH, HEIGHT, s, spheres=spheres)
            ao = renderer.read_ao()
            times.append(time.perf_counter() - t)
        e = ao[ys, xs].astype(np.float64) - ref
        rows[method] = dict(rmse=float(np.sqrt((e * e).mean())), bias=float(e.mean()),
                            frame_ms=1000 * statistics.median(times))
        print(f"    {method:9s}: rmse {rows[method]['rmse']:.4f} bias {rows[method]['bias']:+.4f} "
              f"frame {rows[method]['frame_ms']:.1f} ms", flush=True)
    return rows


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--out", default=str(ROOT / "bench" / "results"))
    args = ap.parse_args()
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    ensure_gpu_context()
    from hao_addon.gpu.hao_renderer import HaoRenderer

    res = dict(machine=dict(platform=platform.platform(), blender=bpy.app.version_string,
                            gpu=gpu.platform.renderer_get()))
    print("sync:", flush=True)
    res["sync_numpy"] = sync_numpy(args.quick)
    res["sync_blender"] = sync_blender()
    ensure_gpu_context()

    print("frame passes (1,000 spheres):", flush=True)
    renderer = HaoRenderer()
    objects, _ = character_scene(10, 64)
    # 1,000 spheres of 2-6 cm over the character's volume (its 3,273 vertices are too few
    # for 1,000 Lloyd clusters of non-zero radius).
    rng = np.random.default_rng(0)
    spheres1000 = (rng.uniform((-0.3, -0.2, 0.0), (0.3, 0.2, 1.5), (1000, 3)), rng.uniform(0.02, 0.06, 1000))
    vp = cm.perspective(0.7, WIDTH / HEIGHT, 0.05, 50.0) @ cm.look_at((1.6, -2.2, 1.3), (0.0, 0.0, 0.7))
    res["frame"] = frame_passes(renderer, objects, vp, spheres1000, 3 if args.quick else 7)
    res["frame"]["far_over_hao_sampling"] = res["frame"]["far_ms"] / res["frame"]["hao_ao_sampling_ms"]
    print(f"  {res['frame']}", flush=True)

    points, rays = (400, 128) if args.quick else (1500, 512)
    res["character"] = {}
    for frame in ((10,) if args.quick else (3, 19, 35)):
        print(f"character frame {frame}:", flush=True)
        objects, spheres = character_scene(frame, 64)
        res["character"][frame] = method_errors(renderer, objects, spheres, vp, METHODS, points, rays, frame)

    print("off-screen occluder (wall behind the camera):", flush=True)
    floor = scenes.grid_plane(4.0, 8, name="floor")
    wall = scenes.box((0.0, -2.0, 0.0), (0.1, 2.0, 1.5), name="wall")  # a 10 cm thick wall
    objs = [object_from_soup(floor, "floor"), object_from_soup(wall, "wall")]
    vp_wall = cm.perspective(0.9, WIDTH / HEIGHT, 0.05, 50.0) @ cm.look_at((-0.05, 0.0, 1.2), (-0.8, 0.0, 0.0))
    res["offscreen"] = method_errors(renderer, objs, None, vp_wall, ("hao", "near"), points, rays, 1,
                                     receivers=lambda pos: pos[..., 0] > -0.8, max_distance=1.0)
    renderer.free()

    (out / "spheres_bench.json").write_text(json.dumps(res, indent=1))
    plot(res, out / "spheres_bench.png")
    print(f"wrote {out / 'spheres_bench.json'} and {out / 'spheres_bench.png'}")
    return 0


def plot(res, path):
    from plot_grid import panel_grid, save
    fig, axes = panel_grid(3)
    ax = axes[0]
    for k in sorted({r["k"] for r in res["sync_numpy"]}):
        rows = [r for r in res["sync_numpy"] if r["k"] == k]
        ax.loglog([r["vertices"] for r in rows], [r["sync_ms"] for r in rows], "o-", label=f"K={k}")
    sb = res["sync_blender"]
    ax.loglog([sb["vertices"]], [sb["per_frame_ms"]], "k*", ms=12, label="in Blender, K=128 (whole path)")
    ax.axhline(5.0, color="gray", ls="--", lw=0.8)
    ax.set_xlabel("vertices")
    ax.set_ylabel("ms per frame")
    ax.set_title("Sphere sync")
    ax.legend(fontsize=8)
    ax = axes[1]
    frames = res["character"]
    for method in METHODS:
        xs = [frames[f][method]["frame_ms"] for f in frames]
        ys = [frames[f][method]["rmse"] for f in frames]
        ax.plot(xs, ys, "o", label=method)
        ax.annotate(method, (np.mean(xs), np.mean(ys)), fontsize=7, textcoords="offset points", xytext=(4, 4))
    ax.set_xlabel("frame ms at 800x600 (all passes)")
    ax.set_ylabel("RMSE vs ray-traced deformed mesh")
    ax.set_title("CesiumMan walk: time against error by method")
    ax.legend(fontsize=8)
    ax = axes[2]
    off = res["offscreen"]
    ax.bar(list(off), [off[m]["rmse"] for m in off])
    ax.set_ylabel("RMSE")
    ax.set_title("Floor before a wall behind the camera")
    save(fig, path)


if __name__ == "__main__":
    sys.exit(main())
