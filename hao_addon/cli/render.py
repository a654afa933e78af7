# SPDX-License-Identifier: GPL-3.0-or-later
"""`render-ao`: viewport AO (HAO) of a scene camera into an image file."""
from __future__ import annotations

import time
from dataclasses import asdict
from pathlib import Path

from .bake import start_gpu, validated
from .errors import CLIError
from .io import check_signals, load_blender, Progress, REPORT, Report
from .options import settings_from_args
from .parser import INPUT_FORMATS
from .scene import check_input, check_json_target, load_scene
from ..core.output_files import check_output_files


def run_render_ao(args, report: Report, progress: Progress) -> list[str]:
    from ..core.imageio import check_writable, write_ao_file
    from ..core.hao.view_settings import RenderSize, ViewAOSettings

    size = validated(settings_from_args(args, RenderSize), RenderSize)
    settings = validated(settings_from_args(args, ViewAOSettings), ViewAOSettings)
    if args.spheres < 0:
        raise CLIError(f"--spheres must be 0 or a positive count, got {args.spheres}")
    report.settings = {**asdict(size), **asdict(settings), "frame": args.frame, "spheres": args.spheres}
    source = check_input(Path(args.input), INPUT_FORMATS)
    report.input = str(source)
    out = check_writable(args.out, size.width, size.height, 4, source=source)
    check_json_target(args.json)
    check_output_files([(str(out), "the AO image (--out)"), (args.json or "", REPORT)],
                       [(str(source), "the input file")])
    bpy = load_blender(report)
    from ..render_ao import render_camera_ao
    with report.phase("load"):
        progress.update("loading")
        load_scene(source)
    check_signals()
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
    if args.spheres:
        from ..blender.sphere_proxies import has_armature, make_proxies
        rigged = [o for o in scene.objects if o.type == 'MESH' and has_armature(o)]
        if not rigged:
            raise CLIError("--spheres: no mesh with an Armature modifier in the scene")
        with report.phase("spheres"):
            for obj in rigged:
                make_proxies(obj, args.spheres)
    start_gpu()
    t0 = time.perf_counter()
    with report.phase("render"):
        progress.update("rendering")
        rgba = render_camera_ao(scene, camera, size.width, size.height, settings, skip_baked=args.skip_baked)
    check_signals()
    with report.phase("write"):
        write_ao_file(out, rgba)
    report.objects.append(dict(camera=camera.name))
    report.outputs.append(str(out))
    return [f"hao: rendered AO from '{camera.name}' {size.width}x{size.height} in "
            f"{time.perf_counter() - t0:.2f} s -> {out}"]
