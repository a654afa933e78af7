# SPDX-License-Identifier: GPL-3.0-or-later
"""Command line: ``python -m hao_addon bake INPUT --size N --directions D --out FILE ...`` and
``python -m hao_addon render-ao INPUT.blend --camera NAME --width W --height H --out FILE ...``.

The same entry point is registered as a Blender command (``blender -c hao bake ...``).
Exit codes: 0 done, 2 bad arguments or input, 3 no usable GPU, 1 anything unexpected.
Errors are one line on stderr: ``hao: error: <what>``.
"""
from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

EXIT_OK, EXIT_FAILURE, EXIT_BAD_INPUT, EXIT_NO_GPU = 0, 1, 2, 3


class CLIError(Exception):
    def __init__(self, message: str, code: int = EXIT_BAD_INPUT) -> None:
        super().__init__(message)
        self.code = code


class _Parser(argparse.ArgumentParser):
    def error(self, message):  # one line, exit 2 (argparse prints usage otherwise)
        raise CLIError(message)


def build_parser() -> argparse.ArgumentParser:
    parser = _Parser(prog="hao", description="GPU ambient occlusion for Blender scenes and meshes.")
    sub = parser.add_subparsers(dest="command", required=True)
    b = sub.add_parser("bake", help="bake per-texel AO of a mesh into an image file")
    b.add_argument("input", help=".obj, .glb/.gltf or .blend file")
    b.add_argument("--out", required=True, help="output .png (16-bit) or .exr (32-bit float)")
    b.add_argument("--size", type=int, default=1024, help="map size in texels (default 1024)")
    b.add_argument("--directions", type=int, default=256, help="light directions (default 256)")
    b.add_argument("--max-distance", type=float, default=0.0, help="occluder reach in scene units; 0 = unlimited")
    b.add_argument("--falloff", choices=("none", "wendland"), default="none")
    b.add_argument("--weighting", choices=("cosine", "uniform"), default="cosine")
    b.add_argument("--ignore-back-faces", action="store_true")
    b.add_argument("--uv-map", default="auto", help="UV map name, or 'auto' (first UV map, else xatlas)")
    b.add_argument("--margin", type=int, default=16, help="texels grown past each UV island (default 16)")
    b.add_argument("--method", choices=("auto", "scatter", "gather"), default="auto",
                   help="auto (default): gather for unlimited distance, scatter with --max-distance")
    b.add_argument("--view-samples", type=float, default=2.0, help="light-view pixels per texel (default 2)")
    b.add_argument("--object", default="", help="mesh to bake (default: the mesh with the most faces)")
    b.add_argument("--occluders", choices=("target", "visible"), default="visible",
                   help="'target': self-occlusion only; 'visible': every visible mesh occludes (default)")
    b.add_argument("--seed", type=int, default=0)
    b.add_argument("--quiet", action="store_true")

    r = sub.add_parser("render-ao", help="render viewport AO (HAO) from a scene camera into an image file")
    r.add_argument("input", help=".blend file (or .obj/.glb: then --camera is required to exist in it)")
    r.add_argument("--out", required=True, help="output .png (16-bit RGBA) or .exr (32-bit float RGBA)")
    r.add_argument("--camera", default="", help="camera object (default: the scene camera)")
    r.add_argument("--width", type=int, default=800)
    r.add_argument("--height", type=int, default=600)
    r.add_argument("--rays", type=int, default=32, help="rays per AO-map pixel (default 32)")
    r.add_argument("--steps", type=int, default=8, help="fixed steps per ray (default 8)")
    r.add_argument("--spread", type=float, default=1.0, help="ray cone, 1 = hemisphere (default 1)")
    r.add_argument("--max-distance", type=float, default=1.0, help="d_max in scene units (default 1)")
    r.add_argument("--grid", type=int, default=256, help="voxels along the longest side, 64..512 (default 256)")
    r.add_argument("--scale", type=int, default=2, help="AO map is 1/scale of the image per axis (default 2)")
    r.add_argument("--filter", type=int, default=16, help="bilateral filter size in pixels (default 16)")
    r.add_argument("--frame", type=int, default=None, help="scene frame to render (default: current)")
    r.add_argument("--skip-baked", action="store_true", help="no HAO on objects that carry a baked AO map")
    r.add_argument("--method", choices=("hao", "near", "far", "near+far", "hao+far"), default="hao",
                   help="hao: voxels (default); near: image-space near field within --max-distance (--rays samples); "
                        "far: sphere proxies; near+far: both; hao+far: spheres for armature meshes, voxels for the rest")
    r.add_argument("--spheres", type=int, default=0,
                   help="sync K sphere proxies on every mesh with an Armature modifier first (0: use those stored)")
    r.add_argument("--epsilon", type=float, default=0.05, help="sphere influence cut-off (default 0.05)")
    r.add_argument("--quiet", action="store_true")
    return parser


def load_scene(path: Path) -> None:
    """Replace the current Blender session with the input file's content."""
    import bpy

    if not path.is_file():
        raise CLIError(f"input file not found: {path}")
    ext = path.suffix.lower()
    if ext == ".blend":
        try:
            bpy.ops.wm.open_mainfile(filepath=str(path), load_ui=False)
        except RuntimeError as exc:
            raise CLIError(f"cannot open '{path}': {str(exc).strip().splitlines()[-1]}") from None
        return
    bpy.ops.wm.read_factory_settings(use_empty=True)
    try:
        if ext == ".obj":
            bpy.ops.wm.obj_import(filepath=str(path))
        elif ext in (".glb", ".gltf"):
            bpy.ops.import_scene.gltf(filepath=str(path))
        else:
            raise CLIError(f"unsupported input '{ext}': use .obj, .glb, .gltf or .blend")
    except RuntimeError as exc:
        raise CLIError(f"cannot import '{path}': {str(exc).strip().splitlines()[-1]}") from None


def pick_target(name: str):
    import bpy

    meshes = [o for o in bpy.context.view_layer.objects if o.type == 'MESH']
    if name:
        obj = bpy.data.objects.get(name)
        if obj is None or obj.type != 'MESH':
            raise CLIError(f"no mesh object named '{name}' (meshes: {', '.join(o.name for o in meshes) or 'none'})")
        return obj
    if not meshes:
        raise CLIError("the input contains no mesh object")
    return max(meshes, key=lambda o: len(o.data.polygons))


def run_bake(args) -> int:
    import bpy

    from .blender.bake_job import BakeJob, BakeRequest
    from .core.settings import BakeSettings

    load_scene(Path(args.input))
    target = pick_target(args.object)
    settings = BakeSettings(size=args.size, directions=args.directions, max_distance=args.max_distance,
                            falloff=args.falloff, weighting=args.weighting,
                            ignore_back_faces=args.ignore_back_faces, margin=args.margin,
                            method=args.method, view_samples=args.view_samples, seed=args.seed)
    out = Path(args.out).resolve()
    request = BakeRequest(targets=[target], settings=settings,
                          occluders="VISIBLE" if args.occluders == "visible" else "TARGET",
                          uv_map="AUTO" if args.uv_map.lower() == "auto" else args.uv_map,
                          filepath=str(out))
    t0 = time.perf_counter()
    job = BakeJob(request, bpy.context.evaluated_depsgraph_get)
    try:
        job.run()
        job.commit()
    except BaseException:
        job.cancel()
        raise
    if not args.quiet:
        _obj, uv_name, result = job.results[0]
        st = result.stats
        print(f"hao: baked '{target.name}' ({st['target_faces']} triangles, UV map '{uv_name}') "
              f"{args.size}x{args.size}, {args.directions} directions in {time.perf_counter() - t0:.2f} s -> {out}")
    return EXIT_OK


def run_render_ao(args) -> int:
    import bpy

    from .core.imageio import format_for_path, write_ao_file
    from .core.view_settings import ViewAOSettings
    from .render_ao import render_camera_ao

    out = Path(args.out).resolve()
    format_for_path(out)  # bad extension: fail before loading anything
    load_scene(Path(args.input))
    scene = bpy.context.scene
    if args.frame is not None:
        scene.frame_set(args.frame)
    if args.camera:
        camera = bpy.data.objects.get(args.camera)
        if camera is None or camera.type != 'CAMERA':
            cams = sorted(o.name for o in bpy.data.objects if o.type == 'CAMERA')
            raise CLIError(f"no camera named '{args.camera}' (cameras: {', '.join(cams) or 'none'})")
    else:
        camera = scene.camera
    settings = ViewAOSettings(rays=args.rays, steps=args.steps, spread=args.spread, max_distance=args.max_distance,
                              grid=args.grid, scale=args.scale, filter_size=args.filter, method=args.method,
                              epsilon=args.epsilon).validated()
    if args.spheres:
        from .blender.sphere_proxies import has_armature, make_proxies
        rigged = [o for o in scene.objects if o.type == 'MESH' and has_armature(o)]
        if not rigged:
            raise CLIError("--spheres: no mesh with an Armature modifier in the scene")
        for obj in rigged:
            make_proxies(obj, args.spheres)
    t0 = time.perf_counter()
    rgba = render_camera_ao(scene, camera, args.width, args.height, settings, skip_baked=args.skip_baked)
    write_ao_file(out, rgba)
    if not args.quiet:
        print(f"hao: rendered AO from '{camera.name}' {args.width}x{args.height} in "
              f"{time.perf_counter() - t0:.2f} s -> {out}")
    return EXIT_OK


def main(argv: list[str] | None = None) -> int:
    argv = list(sys.argv[1:] if argv is None else argv)
    try:
        args = build_parser().parse_args(argv)
        if args.command == "bake":
            return run_bake(args)
        if args.command == "render-ao":
            return run_render_ao(args)
        raise CLIError(f"unknown command {args.command}")
    except CLIError as exc:
        print(f"hao: error: {exc}", file=sys.stderr)
        return exc.code
    except Exception as exc:  # map the library's typed errors to exit codes
        from .core.plan import BakeInputError
        from .gpu.context import GPUUnavailableError
        if isinstance(exc, GPUUnavailableError):
            print(f"hao: error: {exc}", file=sys.stderr)
            return EXIT_NO_GPU
        if isinstance(exc, (BakeInputError, ValueError, OSError, KeyError)):
            msg = str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
            print(f"hao: error: {msg}", file=sys.stderr)
            return EXIT_BAD_INPUT
        raise
