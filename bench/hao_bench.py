# SPDX-License-Identifier: GPL-3.0-or-later
"""Viewport HAO benchmark: per-pass frame times against a Workbench render of the same frame,
accuracy at every distance against ray-traced truth beside EEVEE's AO, the character
methods and their combinations, time against error, and cost against triangle count, all in
one run on one machine.

    .venv/bin/python bench/hao_bench.py [--quick] [--parts frame,distances,character,sweeps,triangles]

Frame: 800x600, the paper's Table 1 settings (AO map 400x300, 32 rays, 256^3 grid, filter 16)
with d_max a third of the bunny's height, each pass timed to completion (a read of its output
forces llvmpipe to finish); the default hierarchical march and the paper's 8 fixed steps;
scenes (each on a floor): the Stanford bunny, a 1M-triangle torus, a multi-object scene.
Distances: d_max in {0.05, 0.3, 1, 3} x the object's height and unlimited, on the bunny, the
multi-object scene and the walking CesiumMan (frames 3, 19, 35; on a 4-unit floor, and on a
40-unit one where the grid over the region starves the character): RMSE of the filtered AO
at 2,000 random visible pixels against a ray-traced reference (512 stratified cosine rays,
the same Wendland kernel and d_max) at the G-buffer's positions and normals; the same for
EEVEE's Ambient Occlusion node (Distance = d_max, the scene's diagonal when unlimited) in an
EEVEE render of the same camera. Character: every method at d_max 0.5 and unlimited.
Writes hao_bench.json and hao_bench.png.
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
from hao_addon.gpu.context import ensure_gpu_context  # noqa: E402

WIDTH, HEIGHT = 800, 600
TABLE1 = ViewAOSettings(rays=32, grid=256, scale=2, filter_size=16)
PAPER_MARCH = dict(march="fixed", steps=8)
DISTANCE_FACTORS = (0.05, 0.3, 1.0, 3.0, 0.0)  # x the object's height; 0 = unlimited
CHARACTER_FRAMES = (3, 19, 35)
CHARACTER_HEIGHT = 1.5  # CesiumMan, scene units
ALL_PARTS = ("frame", "distances", "character", "sweeps", "triangles")


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


# (eye, target, vertical field of view) of the bench scenes and of the character.
BENCH_CAMERA = ((0.16, -0.26, 0.17), (0.0, 0.0, 0.06), 0.75)
CHARACTER_CAMERA = ((1.6, -2.2, 1.3), (0.0, 0.0, 0.7), 0.7)


def view_projection(cam) -> np.ndarray:
    eye, target, fov = cam
    return cm.perspective(fov, WIDTH / HEIGHT, 0.01, 100.0) @ cm.look_at(np.array(eye), np.array(target))


def _finish_texture(tex) -> None:
    """Force completion of what writes `tex` (reading it waits for those commands)."""
    tex.read()


def timed_frame(renderer, objects, view_proj, settings) -> dict:
    """Run every pass from scratch, each timed to completion (ms)."""
    from hao_addon.gpu.hao_composite import draw_composite
    from hao_addon.core.hao.view_scene import filled_classes
    from hao_addon.gpu.hao_renderer import filter_range

    r = renderer
    r.invalidate()
    out = {}
    t = time.perf_counter()
    r.render(objects, view_proj, WIDTH, HEIGHT, settings)  # everything once, uploads included
    out["first_frame_incl_upload"] = 1000 * (time.perf_counter() - t)
    fill = filled_classes(settings.march)
    steps = [("voxelize", lambda: r.voxels.voxelize(r.cascade_specs, fill), lambda: r.voxels.grid),
             ("gbuffer", lambda: r.gbuffer.render(r_view(r, view_proj), WIDTH, HEIGHT), lambda: r.gbuffer.position),
             ("ao", lambda: r.sampling.run(r.gbuffer, r.voxels, settings), lambda: r.sampling.ao_low),
             ("low_gbuffer", lambda: r.low_gbuffer.run(r.gbuffer, settings.scale), lambda: r.low_gbuffer.position),
             ("filter", lambda: r.filter.run(r.gbuffer, r.low_gbuffer, r.sampling.ao_low, settings,
                                             filter_range(settings, r.spec)), lambda: r.filter.ao)]
    for name, run, output in steps:
        t = time.perf_counter()
        run()
        _finish_texture(output())
        out[name] = 1000 * (time.perf_counter() - t)
    colour = gpu.types.GPUTexture((WIDTH, HEIGHT), format='RGBA8')
    fb = gpu.types.GPUFrameBuffer(color_slots=colour)
    with fb.bind():
        fb.clear(color=(0.8, 0.8, 0.8, 1.0))
        t = time.perf_counter()
        draw_composite(r.ao_texture, r.gbuffer.depth, 1.0)
        fb.read_color(0, 0, 1, 1, 4, 0, 'FLOAT')
        out["composite"] = 1000 * (time.perf_counter() - t)
    out["frame"] = sum(out[k] for k in PASSES)
    out["ao_passes"] = out["ao"] + out["filter"]
    out["cascades"] = len(r.cascade_specs)
    return out


PASSES = ("voxelize", "gbuffer", "ao", "low_gbuffer", "filter", "composite")


def r_view(renderer, view_proj) -> np.ndarray:
    """The renderer's anchor-relative view-projection (what its G-buffer pass is given)."""
    shift = np.identity(4)
    shift[:3, 3] = renderer.anchor
    return np.asarray(view_proj, np.float64) @ shift


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


def scene_camera(cam) -> bpy.types.Object:
    """A scene camera with the same projection as view_projection(cam)."""
    import mathutils
    eye, target, fov = cam
    cam_data = bpy.data.cameras.new("cam")
    obj = bpy.data.objects.new("cam", cam_data)
    bpy.context.scene.collection.objects.link(obj)
    obj.location = eye
    obj.rotation_euler = mathutils.Vector(np.subtract(target, eye)).to_track_quat('-Z', 'Y').to_euler()
    cam_data.angle_y = fov
    cam_data.sensor_fit = 'VERTICAL'
    cam_data.clip_start, cam_data.clip_end = 0.01, 100.0
    scene = bpy.context.scene
    scene.camera = obj
    scene.render.resolution_x, scene.render.resolution_y, scene.render.resolution_percentage = WIDTH, HEIGHT, 100
    return obj


def soup_scene(soups: list[TriangleSoup]) -> None:
    """An empty Blender scene holding the soups and the bench camera."""
    bpy.ops.wm.read_factory_settings(use_empty=True)
    for s in soups:
        blender_object(s)
    scene_camera(BENCH_CAMERA)


def workbench_seconds(repeats: int) -> float:
    """Median time of a plain Workbench render of the current scene's frame, anti-aliasing off."""
    scene = bpy.context.scene
    scene.render.engine = 'BLENDER_WORKBENCH'
    scene.display.render_aa = 'OFF'
    bpy.ops.render.render()  # warm-up (shader compilation)
    times = []
    for _ in range(repeats):
        t = time.perf_counter()
        bpy.ops.render.render()
        times.append(time.perf_counter() - t)
    return statistics.median(times)


EEVEE_SAMPLES = 16  # EEVEE's viewport default


def eevee_ao(distance: float, out_dir: Path) -> tuple[float, np.ndarray]:
    """(seconds, (H, W) AO, row 0 at the bottom) of an EEVEE render of the current scene in
    which every mesh shows its Ambient Occlusion node (Distance = distance) as emission,
    Standard view transform, box filter of one pixel."""
    scene = bpy.context.scene
    engines = [e.identifier for e in bpy.types.RenderSettings.bl_rna.properties['engine'].enum_items]
    scene.render.engine = 'BLENDER_EEVEE_NEXT' if 'BLENDER_EEVEE_NEXT' in engines else 'BLENDER_EEVEE'
    scene.eevee.taa_render_samples = EEVEE_SAMPLES
    scene.render.filter_size = 0.0
    scene.view_settings.view_transform = 'Standard'
    mat = bpy.data.materials.get("hao_bench_eevee_ao") or bpy.data.materials.new("hao_bench_eevee_ao")
    mat.use_nodes = True
    nodes = mat.node_tree.nodes
    nodes.clear()
    ao = nodes.new("ShaderNodeAmbientOcclusion")
    emission = nodes.new("ShaderNodeEmission")
    output = nodes.new("ShaderNodeOutputMaterial")
    ao.inputs["Color"].default_value = (1.0, 1.0, 1.0, 1.0)
    ao.inputs["Distance"].default_value = distance
    mat.node_tree.links.new(ao.outputs["Color"], emission.inputs["Color"])
    mat.node_tree.links.new(emission.outputs["Emission"], output.inputs["Surface"])
    for obj in scene.objects:
        if obj.type == 'MESH':
            obj.data.materials.clear()
            obj.data.materials.append(mat)
    scene.render.image_settings.file_format = 'OPEN_EXR'
    path = out_dir / "eevee_ao.exr"
    scene.render.filepath = str(path)
    t = time.perf_counter()
    bpy.ops.render.render(write_still=True)
    seconds = time.perf_counter() - t
    img = bpy.data.images.load(str(path))
    px = np.empty(WIDTH * HEIGHT * 4, np.float32)
    img.pixels.foreach_get(px)
    bpy.data.images.remove(img)
    return seconds, px.reshape(HEIGHT, WIDTH, 4)[..., 0].copy()


_OBJECTS: dict[int, list] = {}


def objects_of(soups):
    key = id(soups)
    if key not in _OBJECTS:
        _OBJECTS[key] = [object_from_soup(s, f"{s.name}{i}") for i, s in enumerate(soups)]
    return _OBJECTS[key]


def character_objects(frame: int, floor: float, k: int = 64):
    """The walking CesiumMan at a frame on a floor `floor` units wide (a Blender scene with
    the bench's character camera), its SceneObjects and its k sphere proxies."""
    from hao_addon.blender import sphere_proxies as sp
    from hao_addon.blender.view_scene import clear_cache, visible_scene_objects
    bpy.ops.wm.read_factory_settings(use_empty=True)
    bpy.ops.import_scene.gltf(filepath=str(ROOT / "tests" / "data" / "CesiumMan.glb"))
    bpy.data.objects["Icosphere"].hide_set(True)
    bpy.ops.mesh.primitive_plane_add(size=floor)
    man = bpy.data.objects["Cesium_Man"]
    sp.make_proxies(man, k)
    bpy.context.scene.frame_set(frame)
    scene_camera(CHARACTER_CAMERA)
    dg = bpy.context.evaluated_depsgraph_get()
    clear_cache()
    objects = visible_scene_objects(dg, bpy.context.view_layer)
    spheres, _ = sp.scene_spheres(bpy.context.view_layer, dg)
    return objects, spheres


def truth_at_pixels(renderer, objects, view_proj, settings, count, rays, seed, spheres=None, mask=None):
    """Random visible pixels of the frame (ys, xs), and the ray-traced AO there (same kernel
    and distance, at the G-buffer's points and normals)."""
    renderer.invalidate()
    renderer.render(objects, view_proj, WIDTH, HEIGHT, settings, spheres=spheres)
    pos, nrm, _ = renderer.gbuffer.read()
    visible = pos[..., 3] >= 1.0
    if mask is not None:
        visible &= mask(pos[..., :3] + renderer.anchor)
    ys, xs = np.nonzero(visible)
    pick = np.random.default_rng(seed).choice(len(ys), min(count, len(ys)), replace=False)
    ys, xs = ys[pick], xs[pick]
    tris = np.concatenate([o.world_positions() for o in objects])
    t = time.perf_counter()
    ref = reference_accessibility(pos[ys, xs, :3].astype(np.float64) + renderer.anchor,
                                  nrm[ys, xs, :3].astype(np.float64), tris, rays=rays,
                                  max_distance=settings.max_distance, falloff=settings.falloff, seed=seed,
                                  bvh=build_bvh(tris))
    return (ys, xs, ref), time.perf_counter() - t


def error_of(ao: np.ndarray, picks) -> dict:
    ys, xs, ref = picks
    e = ao[ys, xs].astype(np.float64) - ref
    return dict(rmse=float(np.sqrt((e * e).mean())), bias=float(e.mean()))


def hao_error(renderer, objects, view_proj, settings, picks, spheres=None) -> dict:
    """Error and the whole frame's time of one render from scratch (uploads excluded)."""
    renderer.invalidate(keep=("upload",))
    renderer.render(objects, view_proj, WIDTH, HEIGHT, settings, spheres=spheres)  # warm (uploads, shaders)
    renderer.invalidate(keep=("upload",))
    t = time.perf_counter()
    renderer.render(objects, view_proj, WIDTH, HEIGHT, settings, spheres=spheres)
    ao = renderer.read_ao()
    seconds = time.perf_counter() - t
    return dict(**error_of(ao, picks), frame_ms=1000 * seconds, cascades=len(renderer.cascade_specs),
                exhausted_rays=renderer.sampling.counts()[1])


def distance_rows(renderer, name, objects, view_proj, height, count, rays, out_dir, seed, spheres=None):
    """Every distance: the default HAO, the paper's march, and EEVEE's AO, against the truth."""
    rows = []
    diagonal = float(np.linalg.norm(np.ptp(np.concatenate([o.world_positions() for o in objects]).reshape(-1, 3),
                                           axis=0)))
    for factor in DISTANCE_FACTORS:
        d = factor * height
        settings = TABLE1.with_(max_distance=d)
        picks, ref_s = truth_at_pixels(renderer, objects, view_proj, settings, count, rays, seed, spheres)
        row = dict(factor=factor, max_distance=d, reference_seconds=ref_s,
                   hao=hao_error(renderer, objects, view_proj, settings, picks, spheres),
                   paper=hao_error(renderer, objects, view_proj, settings.with_(**PAPER_MARCH), picks, spheres))
        seconds, ao = eevee_ao(d if d > 0.0 else diagonal, out_dir)
        row["eevee"] = dict(**error_of(ao, picks), frame_ms=1000 * seconds)
        rows.append(row)
        label = f"{factor:g} x height" if factor else "unlimited"
        print(f"  {name} d_max {label}: hao {row['hao']['rmse']:.4f} ({row['hao']['frame_ms']:.0f} ms, "
              f"{row['hao']['cascades']} cascades), paper march {row['paper']['rmse']:.4f}, "
              f"EEVEE {row['eevee']['rmse']:.4f} ({row['eevee']['frame_ms']:.0f} ms)", flush=True)
    return rows


CHARACTER_METHODS = ("hao", "far", "near", "near+far", "hao+far")


def character_method_rows(renderer, objects, spheres, view_proj, count, rays, seed):
    """Every method at d_max 0.5 and unlimited, over the visible pixels and on the man."""
    rows = {}
    for d in (0.5, 0.0):
        settings = TABLE1.with_(max_distance=d)
        for where, mask in (("visible", None), ("man", lambda p: p[..., 2] > 0.02)):
            picks, _ = truth_at_pixels(renderer, objects, view_proj, settings, count, rays, seed, spheres, mask)
            for method in CHARACTER_METHODS:
                rows.setdefault(f"{d:g}", {}).setdefault(where, {})[method] = hao_error(
                    renderer, objects, view_proj, settings.with_(method=method), picks, spheres)
            got = rows[f"{d:g}"][where]
            print(f"  methods d_max {d:g} ({where}): " + ", ".join(f"{m} {got[m]['rmse']:.4f}" for m in got),
                  flush=True)
    return rows


def main() -> int:
    global WIDTH, HEIGHT
    ap = argparse.ArgumentParser()
    ap.add_argument("--quick", action="store_true", help="fewer repeats and points (smoke test)")
    ap.add_argument("--out", default=str(ROOT / "bench" / "results"))
    ap.add_argument("--parts", default=",".join(ALL_PARTS),
                    help="what to run; the other parts stay as the previous hao_bench.json has them")
    ap.add_argument("--plot-only", action="store_true", help="redraw hao_bench.png from hao_bench.json")
    ap.add_argument("--resolution", default=f"{WIDTH}x{HEIGHT}",
                    help="frame size WxH (tools/gpu_bench.sh: 1920x1080); the AO map is 1/scale of it")
    args = ap.parse_args()
    WIDTH, HEIGHT = (int(v) for v in args.resolution.split("x"))
    if args.plot_only:
        plot(json.loads((Path(args.out) / "hao_bench.json").read_text()), Path(args.out) / "hao_bench.png")
        return 0
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    parts = args.parts.split(",")
    ensure_gpu_context()
    from hao_addon.gpu.hao_renderer import HaoRenderer

    repeats = 2 if args.quick else 5
    count, rays = (500, 256) if args.quick else (2000, 512)
    table1 = TABLE1.with_(max_distance=0.05)  # a third of the bunny's height
    results = dict(machine=dict(platform=platform.platform(), blender=bpy.app.version_string,
                                gpu=gpu.platform.renderer_get()),
                   settings=dict(width=WIDTH, height=HEIGHT, rays=table1.rays, steps=table1.steps, grid=table1.grid,
                                 scale=table1.scale, filter_size=table1.filter_size, max_distance=0.05,
                                 eevee_samples=EEVEE_SAMPLES, reference_rays=rays, points=count))
    previous = out / "hao_bench.json"
    if previous.exists() and set(parts) != set(ALL_PARTS):  # keep the parts not rerun
        kept = json.loads(previous.read_text())
        results = {**{k: v for k, v in kept.items() if k not in results}, **results}
    renderer = HaoRenderer()
    vp = view_projection(BENCH_CAMERA)
    if "frame" in parts:
        results["frame"] = {}
        for name in ("bunny", "torus-1M", "multi-object"):
            soups = scene_soups(name, args.quick)
            hao = median_frame(renderer, objects_of(soups), vp, table1, repeats)
            paper = median_frame(renderer, objects_of(soups), vp, table1.with_(**PAPER_MARCH), repeats)
            soup_scene(soups)
            wb = 1000 * workbench_seconds(repeats)
            ensure_gpu_context()
            tris = int(sum(s.face_count for s in soups))
            results["frame"][name] = dict(triangles=tris, hao=hao, paper=paper, workbench_ms=wb,
                                          hao_over_workbench=hao["frame"] / wb, paper_over_workbench=paper["frame"] / wb)
            print(f"{name}: {tris:,} tris, frame {hao['frame']:.1f} ms ({hao['frame'] / wb:.2f}x Workbench "
                  f"{wb:.1f} ms; " + ", ".join(f"{p} {hao[p]:.1f}" for p in PASSES) +
                  f"); paper march {paper['frame']:.1f} ms", flush=True)
        f = results["frame"]
        results["ao_passes_1M_over_bunny"] = f["torus-1M"]["hao"]["ao_passes"] / f["bunny"]["hao"]["ao_passes"]
    if "distances" in parts:
        results["distances"] = {}
        for name in ("bunny", "multi-object"):
            soups = scene_soups(name, args.quick)
            soup_scene(soups)
            height = float(np.ptp(soups[0].positions[..., 2]))
            results["distances"][name] = dict(height=height, rows=distance_rows(
                renderer, name, objects_of(soups), vp, height, count, rays, out, 3))
        frames = CHARACTER_FRAMES[:1] if args.quick else CHARACTER_FRAMES
        for floor in (4.0, 40.0):
            for frame in frames:
                name = f"character-{floor:g}m-frame{frame}"
                objects, spheres = character_objects(frame, floor)
                results["distances"][name] = dict(height=CHARACTER_HEIGHT, rows=distance_rows(
                    renderer, name, objects, view_projection(CHARACTER_CAMERA), CHARACTER_HEIGHT, count, rays, out,
                    frame))
    if "character" in parts:
        results["character_methods"] = {}
        for frame in (CHARACTER_FRAMES[:1] if args.quick else CHARACTER_FRAMES):
            objects, spheres = character_objects(frame, 4.0)
            results["character_methods"][frame] = character_method_rows(
                renderer, objects, spheres, view_projection(CHARACTER_CAMERA), count, rays, frame)
    if "sweeps" in parts:
        results["sweeps"] = {}
        bunny = scene_soups("bunny", args.quick)
        for param, values in (("grid", [64, 128, 256, 512]), ("rays", [8, 16, 32, 64, 128]),
                              ("steps", [16, 32, 64, 128, 256])):
            rows = []
            for v in values:
                f = median_frame(renderer, objects_of(bunny), vp, table1.with_(**{param: v}), max(1, repeats - 2))
                rows.append(dict(value=v, **f))
                print(f"  sweep {param}={v}: frame {f['frame']:.1f} ms", flush=True)
            results["sweeps"][param] = rows
    if "triangles" in parts:
        results["triangles"] = []
        for seg, sides in ((100, 50), (224, 112), (500, 250), (1000, 500))[: 3 if args.quick else 4]:
            soups = [scenes.torus(0.06, 0.025, (0.0, 0.0, 0.025), seg, sides, name="torus"),
                     scenes.grid_plane(0.6, 4)]
            f = median_frame(renderer, objects_of(soups), vp, table1, max(1, repeats - 2))
            results["triangles"].append(dict(triangles=2 * seg * sides + 32, **f))
            print(f"  triangles {2 * seg * sides:,}: frame {f['frame']:.1f} ms", flush=True)
    renderer.free()
    (out / "hao_bench.json").write_text(json.dumps(results, indent=1))
    plot(results, out / "hao_bench.png")
    print(f"wrote {out / 'hao_bench.json'} and {out / 'hao_bench.png'}")
    return 0


def _rmse_axes(ax, xlabel: str, ylabel: str, title: str, legend_size: int) -> None:
    """Log RMSE axes with the 0.03 target line."""
    ax.axhline(0.03, color="gray", ls="--", lw=0.8)
    ax.set_yscale("log")
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.set_title(title)
    ax.legend(fontsize=legend_size)


def plot(results, path) -> None:
    from plot_grid import panel_grid, save
    panels = [k for k in ("frame", "distances", "character_methods", "triangles") if k in results]
    fig, axes = panel_grid(len(panels))
    for ax, panel in zip(axes, panels):
        if panel == "frame":
            names = list(results["frame"])
            bottom = np.zeros(len(names))
            for p in PASSES:
                vals = np.array([results["frame"][n]["hao"][p] for n in names])
                ax.bar(names, vals, bottom=bottom, label=p)
                bottom += vals
            ax.plot(names, [results["frame"][n]["workbench_ms"] for n in names], "k*", ms=12, label="Workbench")
            ax.plot(names, [3 * results["frame"][n]["workbench_ms"] for n in names], "r_", ms=30, label="3x Workbench")
            ax.set_ylabel(f"ms at {results['settings']['width']}x{results['settings']['height']} (Table 1 settings)")
            ax.set_title("HAO frame by pass vs Workbench")
            ax.legend(fontsize=7)
        elif panel == "distances":
            for i, (name, m) in enumerate(results["distances"].items()):
                labels = [f"{r['factor']:g}" if r["factor"] else "inf" for r in m["rows"]]
                for key, style in (("hao", "o-"), ("paper", "s:"), ("eevee", "^--")):
                    ax.plot(labels, [r[key]["rmse"] for r in m["rows"]], style, color=f"C{i}",
                            label=f"{name} {key}" if key == "hao" or i == 0 else None, alpha=1.0 if key == "hao" else 0.5)
            _rmse_axes(ax, "d_max / object height", "RMSE vs ray-traced truth",
                       "Accuracy at every distance (solid HAO, dotted paper march, dashed EEVEE)", 6)
        elif panel == "character_methods":
            for d, marker in (("0.5", "o"), ("0", "s")):
                for i, m in enumerate(CHARACTER_METHODS):
                    rows = [r[d]["visible"][m] for r in results["character_methods"].values()]
                    ax.scatter([r["frame_ms"] for r in rows], [r["rmse"] for r in rows], marker=marker, color=f"C{i}",
                               label=m if d == "0.5" else None, alpha=0.8)
            _rmse_axes(ax, "frame ms", "RMSE (visible pixels)",
                       "Character methods: d_max 0.5 (circles), unlimited (squares)", 7)
        else:
            tr = results["triangles"]
            for p in PASSES:
                ax.loglog([r["triangles"] for r in tr], [r[p] for r in tr], "o-", label=p)
            ax.set_xlabel("triangles")
            ax.set_ylabel("ms")
            ax.set_title("Pass cost against triangle count")
            ax.legend(fontsize=8)
    save(fig, path)


if __name__ == "__main__":
    sys.exit(main())
