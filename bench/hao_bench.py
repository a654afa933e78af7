# SPDX-License-Identifier: GPL-3.0-or-later
"""Viewport HAO benchmark: per-pass frame times, the paper's sweeps, time against error, and a
Workbench render of the same frame as the yardstick, all in one run on one machine.

    .venv/bin/python bench/hao_bench.py [--quick] [--out bench/results]

Scenes (each on a floor plane): the Stanford bunny (69,451 triangles), a 1M-triangle torus,
and a multi-object scene (bunny, torus, spheres, a wall). Frame: 800x600 with the paper's
Table 1 settings (AO map 400x300, 32 rays, 8 steps, 256^3 grid, filter 16); d_max is a third
of the bunny's height. Each pass is timed to completion (a read of its output forces
llvmpipe to finish). Error: filtered AO at 2,000 random visible pixels against a ray-traced
reference (512 stratified cosine rays, same Wendland kernel and d_max) at the G-buffer's
positions and normals. Writes hao_bench.json and hao_bench.png.
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
from hao_addon.core.geometry import TriangleSoup  # noqa: E402
from hao_addon.core.objfile import obj_soup  # noqa: E402
from hao_addon.core.reference import build_bvh, reference_accessibility  # noqa: E402
from hao_addon.core.hao.view_scene import object_from_soup  # noqa: E402
from hao_addon.core.hao.view_settings import ViewAOSettings  # noqa: E402
from hao_addon.blender.gpu_context import ensure_gpu_context  # noqa: E402

WIDTH, HEIGHT = 800, 600
TABLE1 = ViewAOSettings(rays=32, steps=8, grid=256, scale=2, filter_size=16)


def bunny_soup() -> TriangleSoup:
    soup = obj_soup(ROOT / "bench" / "data" / "stanford-bunny.obj", uvs="none")
    p = soup.positions[..., [0, 2, 1]] * np.array([1.0, -1.0, 1.0])  # y-up -> z-up
    p = p - np.array([0.0, 0.0, p[..., 2].min()])
    return TriangleSoup(p, None, "bunny")


def scene_soups(name: str, quick: bool) -> list[TriangleSoup]:
    floor = scenes.grid_plane(0.6, 4, name="floor")
    if name == "bunny":
        return [bunny_soup(), floor]
    if name == "torus-1M":
        seg, sides = (500, 250) if quick else (1000, 500)
        t = scenes.torus(0.06, 0.025, (0.0, 0.0, 0.025), seg, sides, name="torus")
        return [t, floor]
    bunny = bunny_soup()
    shifted = TriangleSoup(bunny.positions + np.array([-0.08, 0.0, 0.0]), None, "bunny")
    return [shifted, scenes.torus(0.04, 0.015, (0.09, 0.05, 0.015), 96, 48, name="torus"),
            scenes.uv_sphere(0.03, (0.08, -0.07, 0.03), 48, 24, name="ball1"),
            scenes.uv_sphere(0.02, (-0.15, -0.08, 0.02), 48, 24, name="ball2"),
            scenes.wall(0.6, 0.15, 0.2), floor]


def camera() -> np.ndarray:
    eye, target = np.array([0.16, -0.26, 0.17]), np.array([0.0, 0.0, 0.06])
    return eye, target, cm.perspective(0.75, WIDTH / HEIGHT, 0.01, 10.0) @ cm.look_at(eye, target)


def _finish_texture(tex) -> None:
    """Force completion of what writes `tex` (reading it waits for those commands)."""
    tex.read()


def timed_frame(renderer, objects, view_proj, settings) -> dict:
    """Run every pass from scratch, each timed to completion (ms)."""
    from hao_addon.gpu.hao_composite import draw_composite

    r = renderer
    r.invalidate()
    out = {}
    t = time.perf_counter()
    r.render(objects, view_proj, WIDTH, HEIGHT, settings)  # keys cleared: uploads once, then all passes
    out["first_frame_incl_upload"] = 1000 * (time.perf_counter() - t)
    spec = r.spec
    t = time.perf_counter()
    r.voxels.voxelize(spec)
    _finish_texture(r.voxels.grid)
    out["voxelize"] = 1000 * (time.perf_counter() - t)
    t = time.perf_counter()
    r.gbuffer.render(view_proj, WIDTH, HEIGHT)
    r.gbuffer.fb.read_color(0, 0, 1, 1, 4, 0, 'FLOAT')
    out["gbuffer"] = 1000 * (time.perf_counter() - t)
    t = time.perf_counter()
    r.sampling.run(r.gbuffer, r.voxels, settings)
    _finish_texture(r.sampling.ao_low)
    out["ao"] = 1000 * (time.perf_counter() - t)
    t = time.perf_counter()
    r.filter.run(r.gbuffer, r.sampling.ao_low, settings)
    _finish_texture(r.filter.ao)
    out["filter"] = 1000 * (time.perf_counter() - t)
    colour = gpu.types.GPUTexture((WIDTH, HEIGHT), format='RGBA8')
    fb = gpu.types.GPUFrameBuffer(color_slots=colour)
    with fb.bind():
        fb.clear(color=(0.8, 0.8, 0.8, 1.0))
        t = time.perf_counter()
        draw_composite(r.ao_texture, r.gbuffer.depth, 1.0)
        fb.read_color(0, 0, 1, 1, 4, 0, 'FLOAT')
        out["composite"] = 1000 * (time.perf_counter() - t)
    out["frame"] = sum(out[k] for k in ("voxelize", "gbuffer", "ao", "filter", "composite"))
    out["ao_passes"] = out["ao"] + out["filter"]
    return out


def median_frame(renderer, objects, view_proj, settings, repeats: int) -> dict:
    runs = [timed_frame(renderer, objects, view_proj, settings) for _ in range(repeats)]
    return {k: statistics.median(r[k] for r in runs) for k in runs[0]}


def blender_object(soup: TriangleSoup) -> bpy.types.Object:
    """A Blender mesh of the soup (welded), built with foreach_set (1M triangles in seconds)."""
    pos = soup.positions.reshape(-1, 3)
    verts, inverse = np.unique(pos, axis=0, return_inverse=True)
    mesh = bpy.data.meshes.new(soup.name)
    mesh.vertices.add(len(verts))
    mesh.vertices.foreach_set("co", verts.astype(np.float32).ravel())
    mesh.loops.add(len(inverse))
    mesh.loops.foreach_set("vertex_index", inverse.astype(np.int32).ravel())
    mesh.polygons.add(len(soup.positions))
    mesh.polygons.foreach_set("loop_start", np.arange(0, len(inverse), 3, dtype=np.int32))
    mesh.update()
    obj = bpy.data.objects.new(soup.name, mesh)
    bpy.context.scene.collection.objects.link(obj)
    return obj


def workbench_seconds(soups: list[TriangleSoup], repeats: int) -> float:
    """Median time of a plain Workbench render of the same frame, anti-aliasing off."""
    bpy.ops.wm.read_factory_settings(use_empty=True)
    for s in soups:
        blender_object(s)
    eye, target, _ = camera()
    cam_data = bpy.data.cameras.new("cam")
    cam = bpy.data.objects.new("cam", cam_data)
    bpy.context.scene.collection.objects.link(cam)
    cam.location = eye
    direction = target - eye
    import mathutils
    cam.rotation_euler = mathutils.Vector(direction).to_track_quat('-Z', 'Y').to_euler()
    cam_data.angle_y = 0.75
    cam_data.sensor_fit = 'VERTICAL'
    scene = bpy.context.scene
    scene.camera = cam
    scene.render.engine = 'BLENDER_WORKBENCH'
    scene.display.render_aa = 'OFF'
    scene.render.resolution_x, scene.render.resolution_y, scene.render.resolution_percentage = WIDTH, HEIGHT, 100
    bpy.ops.render.render()  # warm-up (shader compilation)
    times = []
    for _ in range(repeats):
        t = time.perf_counter()
        bpy.ops.render.render()
        times.append(time.perf_counter() - t)
    return statistics.median(times)


def error_against_reference(renderer, soups, settings, picks, bvh, rays) -> float:
    renderer.invalidate()
    _, _, vp = camera()
    renderer.render(objects_of(soups), vp, WIDTH, HEIGHT, settings)
    ao = renderer.read_ao()
    ys, xs, ref = picks
    e = ao[ys, xs].astype(np.float64) - ref
    return float(np.sqrt((e * e).mean()))


_OBJECTS: dict[int, list] = {}


def objects_of(soups):
    key = id(soups)
    if key not in _OBJECTS:
        _OBJECTS[key] = [object_from_soup(s, f"{s.name}{i}") for i, s in enumerate(soups)]
    return _OBJECTS[key]


def reference_picks(renderer, soups, settings, count, rays, seed=3):
    renderer.invalidate()
    _, _, vp = camera()
    renderer.render(objects_of(soups), vp, WIDTH, HEIGHT, settings)
    pos, nrm, _ = renderer.gbuffer.read()
    ys, xs = np.nonzero(pos[..., 3] >= 1.0)
    rng = np.random.default_rng(seed)
    pick = rng.choice(len(ys), min(count, len(ys)), replace=False)
    ys, xs = ys[pick], xs[pick]
    tris = np.concatenate([s.positions for s in soups])
    t = time.perf_counter()
    ref = reference_accessibility(pos[ys, xs, :3].astype(np.float64), nrm[ys, xs, :3].astype(np.float64), tris,
                                  rays=rays, max_distance=settings.max_distance, falloff="wendland", seed=seed,
                                  bvh=build_bvh(tris))
    return (ys, xs, ref), time.perf_counter() - t


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--quick", action="store_true", help="fewer repeats and points (smoke test)")
    ap.add_argument("--out", default=str(ROOT / "bench" / "results"))
    args = ap.parse_args()
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    ensure_gpu_context()
    from hao_addon.gpu.hao_renderer import HaoRenderer

    repeats = 2 if args.quick else 5
    d_max = 0.05  # a third of the bunny's height
    table1 = TABLE1.with_(max_distance=d_max)
    results = dict(machine=dict(platform=platform.platform(), blender=bpy.app.version_string,
                                gpu=gpu.platform.renderer_get()),
                   settings=dict(width=WIDTH, height=HEIGHT, rays=table1.rays, steps=table1.steps, grid=table1.grid,
                                 scale=table1.scale, filter_size=table1.filter_size, max_distance=d_max),
                   scenes={}, sweeps={}, error={}, triangles=[])
    renderer = HaoRenderer()
    _, _, vp = camera()
    soups_by_scene = {}
    for name in ("bunny", "torus-1M", "multi-object"):
        soups = scene_soups(name, args.quick)
        soups_by_scene[name] = soups
        frame = median_frame(renderer, objects_of(soups), vp, table1, repeats)
        wb = workbench_seconds(soups, repeats)
        ensure_gpu_context()
        tris = int(sum(s.face_count for s in soups))
        results["scenes"][name] = dict(triangles=tris, passes_ms=frame, workbench_ms=1000 * wb,
                                       frame_over_workbench=frame["frame"] / (1000 * wb))
        print(f"{name}: {tris:,} tris, frame {frame['frame']:.1f} ms "
              f"(vox {frame['voxelize']:.1f}, gbuf {frame['gbuffer']:.1f}, ao {frame['ao']:.1f}, "
              f"filter {frame['filter']:.1f}, comp {frame['composite']:.1f}); workbench {1000 * wb:.1f} ms", flush=True)
    b, t1m = results["scenes"]["bunny"], results["scenes"]["torus-1M"]
    results["ao_passes_1M_over_bunny"] = t1m["passes_ms"]["ao_passes"] / b["passes_ms"]["ao_passes"]

    # The paper's sweeps (Figure 6) on the bunny: one parameter at a time.
    bunny = soups_by_scene["bunny"]
    for param, values in (("grid", [64, 128, 256, 512]), ("rays", [8, 16, 32, 64, 128]),
                          ("filter_size", [0, 4, 8, 16, 32])):
        rows = []
        for v in values:
            f = median_frame(renderer, objects_of(bunny), vp, table1.with_(**{param: v}), max(1, repeats - 2))
            rows.append(dict(value=v, **f))
            print(f"  sweep {param}={v}: frame {f['frame']:.1f} ms", flush=True)
        results["sweeps"][param] = rows

    # Time against error on the bunny (and the multi-object scene at Table 1).
    count, rays = (500, 256) if args.quick else (2000, 512)
    for name in ("bunny", "multi-object"):
        soups = soups_by_scene[name]
        picks, ref_s = reference_picks(renderer, soups, table1, count, rays)
        rows = []
        variants = [("table1", {})] + ([] if name != "bunny" else
                                        [(f"rays={v}", dict(rays=v)) for v in (8, 16, 64, 128)]
                                        + [(f"steps={v}", dict(steps=v)) for v in (4, 16, 32)]
                                        + [(f"grid={v}", dict(grid=v)) for v in (64, 128, 512)])
        for label, change in variants:
            s = table1.with_(**change)
            f = median_frame(renderer, objects_of(soups), vp, s, max(1, repeats - 2))
            err = error_against_reference(renderer, soups, s, picks, None, rays)
            rows.append(dict(label=label, **change, frame_ms=f["frame"], ao_passes_ms=f["ao_passes"], rmse=err))
            print(f"  error {name} {label}: rmse {err:.4f}, frame {f['frame']:.1f} ms", flush=True)
        results["error"][name] = dict(reference_rays=rays, points=count, reference_seconds=ref_s, runs=rows)

    # Cost against triangle count: tori from 10k to 1M triangles on the floor.
    for seg, sides in ((100, 50), (224, 112), (500, 250), (1000, 500))[: 3 if args.quick else 4]:
        soups = [scenes.torus(0.06, 0.025, (0.0, 0.0, 0.025), seg, sides, name="torus"), scenes.grid_plane(0.6, 4)]
        f = median_frame(renderer, objects_of(soups), vp, table1, max(1, repeats - 2))
        results["triangles"].append(dict(triangles=2 * seg * sides + 32, **f))
        print(f"  triangles {2 * seg * sides:,}: frame {f['frame']:.1f} ms", flush=True)
    renderer.free()

    (out / "hao_bench.json").write_text(json.dumps(results, indent=1))
    plot(results, out / "hao_bench.png")
    print(f"wrote {out / 'hao_bench.json'} and {out / 'hao_bench.png'}")
    return 0


def plot(results, path) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(1, 4, figsize=(22, 4.8))
    ax = axes[0]
    names = list(results["scenes"])
    passes = ("voxelize", "gbuffer", "ao", "filter", "composite")
    bottom = np.zeros(len(names))
    for p in passes:
        vals = np.array([results["scenes"][n]["passes_ms"][p] for n in names])
        ax.bar(names, vals, bottom=bottom, label=p)
        bottom += vals
    ax.plot(names, [results["scenes"][n]["workbench_ms"] for n in names], "k*", ms=12, label="Workbench render")
    ax.set_ylabel("ms at 800x600 (Table 1 settings)")
    ax.set_title("HAO frame by pass vs Workbench")
    ax.legend(fontsize=8)
    ax = axes[1]
    for param, rows in results["sweeps"].items():
        t0 = rows[0]["value"]
        ax.plot([r["value"] for r in rows], [r["frame"] for r in rows], "o-", label=param)
        del t0
    ax.set_xscale("symlog", base=2)
    ax.set_xlabel("parameter value (grid / rays / filter size)")
    ax.set_ylabel("frame ms")
    ax.set_title("Paper's sweeps (bunny)")
    ax.legend(fontsize=8)
    ax = axes[2]
    runs = results["error"]["bunny"]["runs"]
    for prefix, style in (("rays", "o-"), ("steps", "s-"), ("grid", "^-")):
        sel = [r for r in runs if r["label"].startswith(prefix)] + [runs[0]]
        sel.sort(key=lambda r: r.get(prefix, results["settings"][prefix]))
        ax.plot([r["frame_ms"] for r in sel], [r["rmse"] for r in sel], style, label=f"vary {prefix}")
        for r in sel:
            ax.annotate(r["label"], (r["frame_ms"], r["rmse"]), fontsize=6, textcoords="offset points", xytext=(3, 3))
    ax.axhline(0.05, color="gray", ls="--", lw=0.8)
    ax.set_xlabel("frame ms")
    ax.set_ylabel("RMSE vs ray-traced reference")
    ax.set_title("Time against error (bunny)")
    ax.legend(fontsize=8)
    ax = axes[3]
    tr = results["triangles"]
    for p in passes:
        ax.loglog([r["triangles"] for r in tr], [r[p] for r in tr], "o-", label=p)
    ax.set_xlabel("triangles")
    ax.set_ylabel("ms")
    ax.set_title("Pass cost against triangle count")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=100)


if __name__ == "__main__":
    sys.exit(main())
