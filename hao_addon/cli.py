# SPDX-License-Identifier: GPL-3.0-or-later
"""Command line: ``python -m hao_addon bake INPUT --out FILE ...`` and
``python -m hao_addon render-ao INPUT.blend --out FILE ...``.

The same entry point is registered as a Blender command (``blender -c hao bake ...``).
Exit codes: 0 done, 1 internal error, 2 bad arguments or input, 3 no usable GPU,
130 / 143 interrupted by SIGINT / SIGTERM. Every failure is one line on stderr,
``hao: error: <what>``, with nothing written; a successful ``--quiet`` run prints nothing.
"""
from __future__ import annotations

import argparse
import os
import re
import sys
import time
import traceback
from dataclasses import asdict, replace
from pathlib import Path

from . import __version__
from .cli_io import (EXIT_INTERRUPTED, REPORT, OpenJDProgress, ProcessOutput, Progress, Report, Terminated,
                     check_signals,
                     deferred_signals, pending_signal, signals_as_exceptions)
from .cli_options import add_setting_options, option_for, settings_from_args
from .core.bake.tangent_space import CONVENTION_CHOICES, SPACE_CHOICES
from .core.errors import BakeInputError
from .core.frame_ranges import parse_frames
from .core.output_files import FRAME_TOKEN, INPUT_TOKEN, OBJECT_TOKEN, OutputCollision, check_output_files
from .core.setting_spec import SettingError

EXIT_OK, EXIT_FAILURE, EXIT_BAD_INPUT, EXIT_NO_GPU = 0, 1, 2, 3
# A batch's file names in --out-dir, unless --out gives them ({input}: the input's name without
# extension, cleaned for file names as object names are).
BATCH_NAME = "{input}_ao.png"  # several meshes of an input: _{object} is added
INPUT_FORMATS = (".obj", ".glb", ".gltf", ".blend")
GLTF_OUT = "the glTF file (--gltf-out)"  # its name in collision messages
DEBUG_ENV = "HAO_DEBUG"  # set to 1: an internal error also prints its traceback and Blender's log


class CLIError(Exception):
    def __init__(self, message: str, code: int = EXIT_BAD_INPUT) -> None:
        super().__init__(message)
        self.code = code


class _Parser(argparse.ArgumentParser):
    def error(self, message):  # one line, exit 2 (argparse prints usage otherwise)
        raise CLIError(message)


def build_parser() -> argparse.ArgumentParser:
    from .core.hao.view_settings import RenderSize, ViewAOSettings

    parser = _Parser(prog="hao", description="GPU ambient occlusion for Blender scenes and meshes.")
    parser.add_argument("--version", action="version", version=f"hao {__version__}")
    sub = parser.add_subparsers(dest="command", required=True)
    b = sub.add_parser("bake", help="bake per-texel AO of a mesh into an image file")
    add_bake_arguments(b)
    b.add_argument("--manifest", default=None, metavar="FILE",
                   help="a farm task: bake chunk --chunk of this job manifest (written by 'farm'), its inputs "
                        "relative to --input-root (default: the manifest's root), into --out-dir")
    b.add_argument("--chunk", type=int, default=0, help="with --manifest: the chunk to bake (0 is the first)")
    b.add_argument("--input-root", default=None, metavar="DIR", help="with --manifest: the folder of its inputs")
    b.add_argument("--progress", choices=("terminal", "openjd"), default="terminal",
                   help="terminal: a progress line on a terminal; openjd: 'openjd_progress: P' lines on stdout "
                        "(Open Job Description's form, for farm tasks)")
    _add_run_options(b)

    from .cli_farm import add_farm_parsers
    add_farm_parsers(sub, add_bake_arguments, _add_run_options)

    r = sub.add_parser("render-ao", help="render viewport AO (HAO) from a scene camera into an image file")
    r.add_argument("input", help=".blend file (or .obj/.glb with a camera in it)")
    r.add_argument("--out", required=True, help="output .png (16-bit RGBA) or .exr (32-bit float RGBA)")
    r.add_argument("--camera", default="", help="camera object (default: the scene camera)")
    add_setting_options(r, RenderSize)
    add_setting_options(r, ViewAOSettings)
    r.add_argument("--frame", type=int, default=None, help="scene frame to render (default: current)")
    r.add_argument("--skip-baked", action="store_true", help="no HAO on objects that carry a baked AO map")
    r.add_argument("--spheres", type=int, default=0,
                   help="sync K sphere proxies on every mesh with an Armature modifier first (0: use those stored)")
    _add_run_options(r)
    return parser


def add_bake_arguments(b: argparse.ArgumentParser) -> None:
    """What a bake takes (bake, and the farm commands that write bake jobs): inputs, outputs,
    frames and every bake setting."""
    from .core.bake.settings import BakeSettings

    b.add_argument("input", nargs="*", help=".obj, .glb/.gltf or .blend file; several make a batch (--out-dir)")
    b.add_argument("--out", default=None,
                   help="output .png (16-bit) or .exr (32-bit float); {object} becomes the baked object's name, "
                        "{input} the input file's name without extension. With --target color-attribute: the "
                        "mesh file to save, .blend (the whole scene), .glb (COLOR_0) or .ply (vertex colours). "
                        f"With --out-dir: a file name in it (default {BATCH_NAME})")
    b.add_argument("--out-dir", default=None, metavar="DIR",
                   help="a batch: every input is baked (a failed one does not stop the others; exit 1 if any "
                        "failed), its files written into DIR as --out names them")
    b.add_argument("--frames", default=None, metavar="A-B[:STEP][,...]",
                   help="bake frames A to B (every STEP-th; several ranges joined by commas, Open Job "
                        "Description's syntax: 1-3,5,7-20:2) of the scene's animation, one map per frame: "
                        "{frame} in --out becomes the frame, zero-padded to 4 digits (else _{frame} is added); a "
                        "frame whose evaluated meshes equal an earlier one's reuses its bake")
    b.add_argument("--skip-existing", action="store_true",
                   help="bake only what is missing: an output whose file exists and was made from the same input "
                        "files and settings (a key in its metadata) is kept, as is each such frame of --frames; "
                        "other files are baked again (a re-queued farm task redoes only what is missing)")
    b.add_argument("--all-meshes", action="store_true",
                   help="bake every mesh of each input (each into its own file), not only the largest")
    add_setting_options(b, BakeSettings)
    b.add_argument("--uv-map", default="auto", help="UV map name, or 'auto' (first UV map, else xatlas)")
    b.add_argument("--object", action="append", default=None, metavar="NAME",
                   help="mesh to bake (default: the mesh with the most faces); repeatable: each into its own "
                        "file ({object} in --out, else _NAME is added), or with --texture-set all into one")
    b.add_argument("--texture-set", action="store_true",
                   help="bake the --object meshes together into one shared image (their UV islands must not "
                        "overlap across objects); {object} in file names becomes 'TextureSet'")
    b.add_argument("--occluders", choices=("target", "visible"), default="visible",
                   help="target: self-occlusion only (with --high-poly: the high-poly only); visible: every "
                        "visible mesh occludes (default)")
    b.add_argument("--high-poly", action="append", default=None, metavar="PATH_OR_NAME",
                   help="Selected to Active: bake this high-poly onto the low-poly's UVs (repeatable): a "
                        ".obj/.glb/.gltf/.blend file whose meshes are the sources, or the name of a mesh in INPUT; "
                        "the low-poly (--object, default the largest other mesh) does not occlude")
    b.add_argument("--cage", default="", metavar="NAME",
                   help="Selected to Active: a mesh in INPUT with the low-poly's topology that the rays start from "
                        "(instead of --cage-extrusion)")
    b.add_argument("--bent-normal-out", default="", metavar="FILE",
                   help="also bake bent normals (the cosine-weighted mean unoccluded direction, same pass) into "
                        "this .png (16-bit) or .exr (32-bit float) RGB file, 0.5 + 0.5 n; {object} as in --out")
    b.add_argument("--gltf-out", default="", metavar="FILE.glb",
                   help="also write the baked object as a .glb with the map as its material's occlusionTexture "
                        "(Blender's glTF exporter; the map on the UV map that was baked)")
    for option, choices in (("--bent-space", SPACE_CHOICES), ("--bent-convention", CONVENTION_CHOICES)):
        b.add_argument(option, choices=[c.value for c in choices], default=choices[0].value,
                       help="; ".join(f"{c.value}: {c.description}" for c in choices) + f" (default {choices[0].value})")


def _add_run_options(p: argparse.ArgumentParser) -> None:
    p.add_argument("--json", default=None, metavar="PATH",
                   help="write a machine-readable report to PATH ('-': standard output)")
    p.add_argument("--quiet", action="store_true", help="print nothing unless it fails")


# -- input and output checks (before anything is loaded) --------------------------------------------

def check_input(path: Path, allowed: tuple[str, ...]) -> Path:
    if not path.exists():
        raise CLIError(f"input file not found: {path}")
    if path.is_dir():
        raise CLIError(f"input '{path}' is a folder, not a file")
    if path.suffix.lower() not in allowed:
        raise CLIError(f"unsupported input '{path.suffix}': use {', '.join(allowed)}")
    if not os.access(path, os.R_OK):
        raise CLIError(f"cannot read '{path}': permission denied")
    if path.stat().st_size == 0:
        raise CLIError(f"input '{path}' is empty")
    return path.resolve()


def check_json_target(spec: str | None) -> None:
    if spec in (None, "-"):
        return
    folder = Path(os.path.abspath(spec)).parent
    if not folder.is_dir():
        raise CLIError(f"cannot write the report '{spec}': folder does not exist")
    if Path(spec).is_dir() or not os.access(folder, os.W_OK):
        raise CLIError(f"cannot write the report '{spec}'")


def load_scene(path: Path) -> None:
    """Replace the current Blender session with the input file's content."""
    import bpy

    ext = path.suffix.lower()
    try:
        if ext == ".blend":
            bpy.ops.wm.open_mainfile(filepath=str(path), load_ui=False)
            return
        bpy.ops.wm.read_factory_settings(use_empty=True)
        check_signals()  # it registers the bundled add-ons: one interrupted there is missing
        if ext == ".obj":
            bpy.ops.wm.obj_import(filepath=str(path))
        else:
            bpy.ops.import_scene.gltf(filepath=str(path))
    except (RuntimeError, ValueError, KeyError, OSError, UnicodeError) as exc:  # the importers' own errors
        check_signals()  # a Python importer interrupted by Ctrl-C fails with Blender's RuntimeError
        raise CLIError(f"cannot read '{path.name}': {_last_line(exc)}") from None


def _last_line(exc: BaseException) -> str:
    lines = [l.strip() for l in str(exc).strip().splitlines() if l.strip()]
    text = lines[-1] if lines else type(exc).__name__
    return text.removeprefix("Error: ")


def import_meshes(path: Path) -> list:
    """Add the meshes of a .obj/.glb/.gltf/.blend file to the current scene; returns them."""
    import bpy

    before = set(bpy.data.objects)
    try:
        ext = path.suffix.lower()
        if ext == ".blend":
            with bpy.data.libraries.load(str(path)) as (data_from, data_to):
                data_to.objects = list(data_from.objects)
            for obj in data_to.objects:
                if obj is not None and obj.type == 'MESH':
                    bpy.context.scene.collection.objects.link(obj)
        elif ext == ".obj":
            bpy.ops.wm.obj_import(filepath=str(path))
        else:
            bpy.ops.import_scene.gltf(filepath=str(path))
    except (RuntimeError, ValueError, KeyError, OSError, UnicodeError) as exc:
        check_signals()
        raise CLIError(f"cannot read '{path.name}': {_last_line(exc)}") from None
    check_signals()
    meshes = [o for o in bpy.data.objects if o not in before and o.type == 'MESH']
    if not meshes:
        raise CLIError(f"--high-poly '{path.name}' holds no mesh")
    return meshes


def pick_high_poly(specs: list[str]) -> list:
    """The Selected-to-Active sources: each spec a mesh file to add, or a mesh's name."""
    import bpy

    out = []
    for spec in specs:
        path = Path(spec)
        if path.suffix.lower() in INPUT_FORMATS and bpy.data.objects.get(spec) is None:
            try:
                checked = check_input(path, INPUT_FORMATS)
            except CLIError as exc:
                raise CLIError(f"--high-poly: {exc}") from None
            out += import_meshes(checked)
            continue
        obj = bpy.data.objects.get(spec)
        if obj is None or obj.type != 'MESH':
            raise CLIError(f"--high-poly '{spec}' is neither a mesh file nor a mesh in the input "
                           f"(meshes: {_mesh_names()})")
        out.append(obj)
    return out


def pick_mesh(name: str, option: str):
    import bpy

    obj = bpy.data.objects.get(name)
    if obj is None or obj.type != 'MESH':
        raise CLIError(f"{option}: no mesh object named '{name}' (meshes: {_mesh_names()})")
    return obj


def _mesh_names() -> str:
    """The scene's mesh objects, for messages that name a missing one."""
    import bpy

    return ", ".join(o.name for o in bpy.context.view_layer.objects if o.type == 'MESH') or "none"


# The files a colour-attribute bake saves its mesh to (--target color-attribute --out FILE).
MESH_OUT_FORMATS = (".blend", ".glb", ".ply")


def check_mesh_target(path: str, source: Path, allowed: tuple[str, ...], option: str) -> Path:
    """A mesh file to write (--gltf-out, or --out of a colour-attribute bake), refused before
    any work unless its extension is allowed, its folder writable and it is not the input."""
    out = Path(os.path.abspath(path))
    if out.suffix.lower() not in allowed:
        raise CLIError(f"{option} must be a {' or '.join(allowed)} file (one file, written atomically), got '{path}'")
    if not out.parent.is_dir() or not os.access(out.parent, os.W_OK):
        raise CLIError(f"cannot write '{out}': its folder does not exist or is not writable")
    if out.exists() and out.resolve() == source.resolve():
        raise CLIError(f"{option} '{out}' is the input file")
    return out


def check_gltf_target(path: str, source: Path) -> Path:
    """The --gltf-out file: a .glb (check_mesh_target)."""
    return check_mesh_target(path, source, (".glb",), "--gltf-out")


def export_mesh_file(objects: list, path: Path, colors: bool = False) -> None:
    """Write the objects alone as a .glb (Blender's glTF exporter; colors: with their active
    colour attribute as COLOR_0) or a .ply (linear vertex colours when colors), or the whole
    session as a .blend copy; atomically (a temporary file in the same folder, renamed over
    path)."""
    import bpy

    for other in bpy.context.view_layer.objects:
        other.select_set(other in objects)
    bpy.context.view_layer.objects.active = objects[0]
    obj = objects[0]
    suffix = path.suffix.lower()
    tmp = path.with_name(f".{path.stem}.hao-{os.getpid()}{suffix}")
    try:
        if suffix == ".glb":
            extra = {"export_vertex_color": 'ACTIVE'} if colors else {}
            result = bpy.ops.export_scene.gltf(filepath=str(tmp), export_format='GLB', use_selection=True, **extra)
        elif suffix == ".ply":
            result = bpy.ops.wm.ply_export(filepath=str(tmp), export_selected_objects=True,
                                           export_colors='LINEAR' if colors else 'NONE')
        else:
            result = bpy.ops.wm.save_as_mainfile(filepath=str(tmp), copy=True, check_existing=False)
        if result != {'FINISHED'} or not tmp.is_file():
            raise CLIError(f"writing '{obj.name}' to {path.name} failed")
        os.replace(tmp, path)
    finally:
        if tmp.exists():
            tmp.unlink()


def export_glb(objects: list, path: Path) -> None:
    """Write the objects alone as a .glb with their baked maps (export_mesh_file)."""
    export_mesh_file(objects, path)


def pick_target(name: str, exclude: tuple = ()):
    """The mesh to bake: by name, else the one with the most faces (not among exclude)."""
    import bpy

    if name:
        obj = bpy.data.objects.get(name)
        if obj is None or obj.type != 'MESH':
            raise CLIError(f"no mesh object named '{name}' (meshes: {_mesh_names()})")
        return obj
    meshes = [o for o in bpy.context.view_layer.objects if o.type == 'MESH' and o not in exclude]
    if not meshes:
        raise CLIError("the input contains no mesh object")
    return max(meshes, key=lambda o: len(o.data.polygons))


# -- commands ---------------------------------------------------------------------------------------

def run_bake(args, report: Report, progress: Progress) -> list[str]:
    """Bake; returns the summary lines to print."""
    import bpy

    from .blender.bake_job import BakeJob, BakeRequest, output_path_for
    from .cli_skip import run_key, skip_finished
    from .core.imageio import BAKE_KEY
    from .blender.color_attributes import AO_ATTRIBUTE
    from .blender.paths import example_path, frame_pattern
    from .core.imageio import check_writable
    from .core.bake.settings import BakeSettings

    settings = _validated(settings_from_args(args, BakeSettings), BakeSettings)
    source = check_input(Path(args.input), INPUT_FORMATS)
    frames = parse_frames(args.frames) if args.frames else None
    first_frame = frames[0] if frames else 0
    if source.suffix.lower() != ".blend":  # imported objects carry no terminator offset of their own
        settings = replace(settings, terminator="setting")
    to_colors = settings.target == "color-attribute"
    if to_colors and (args.bent_normal_out or args.gltf_out):
        raise CLIError("--target color-attribute writes the mesh with its colour attribute to --out "
                       "(.blend, .glb or .ply); --bent-normal-out and --gltf-out are image bakes")
    if args.bent_normal_out:
        settings = replace(settings, bent_normals=True)
        check_writable(example_path(args.bent_normal_out, first_frame), settings.size, settings.size, 4,
                       source=source)
    gltf_out = check_gltf_target(args.gltf_out, source) if args.gltf_out else None
    report.settings = {**asdict(settings), "uv_map": args.uv_map, "occluders": args.occluders}
    report.input = str(source)
    # Refused before a long load; checked again with the object's name once it is known.
    mesh_out = check_mesh_target(args.out, source, MESH_OUT_FORMATS, "--out") if to_colors else None
    if not to_colors:
        check_writable(example_path(args.out, first_frame), settings.size, settings.size, 1, source=source)
    check_json_target(args.json)
    reads, writes = _bake_files(args, source, mesh_out, gltf_out)
    literal = [(path, what) for path, what in _image_outputs(args, to_colors) if not _has_token(path)]
    check_output_files(writes + literal, reads)  # again with every file once the objects are known (BakeJob)
    key = run_key(args, [Path(path) for path, _what in reads])
    with report.phase("load"):
        progress.update("loading")
        load_scene(source)
    check_signals()
    high_poly = pick_high_poly(args.high_poly) if args.high_poly else None
    cage = pick_mesh(args.cage, "--cage") if args.cage else None
    if cage is not None and high_poly is None:
        raise CLIError("--cage needs --high-poly (Selected to Active)")
    exclude = tuple(high_poly or ()) + ((cage,) if cage else ())
    if args.all_meshes:
        targets = [o for o in bpy.context.view_layer.objects if o.type == 'MESH' and o not in exclude]
        if not targets:
            raise CLIError("the input contains no mesh object")
    else:
        targets = [pick_target(name, exclude) for name in (args.object or [""])]
    if len({o.name for o in targets}) != len(targets):
        raise CLIError("--object names the same mesh twice")
    if args.texture_set and len(targets) < 2:
        raise CLIError("--texture-set bakes several meshes into one image: name them with --object (twice or more)")
    if high_poly is not None and len(targets) > 1:
        raise CLIError("Selected to Active bakes onto one low-poly: give one --object")
    if high_poly is not None:
        report.settings["high_poly"] = [o.name for o in high_poly]
        report.settings["cage"] = cage.name if cage else ""
    request = BakeRequest(targets=targets, settings=settings, texture_set=args.texture_set,
                          frames=frames,
                          occluders="VISIBLE" if args.occluders == "visible" else "TARGET",
                          uv_map="AUTO" if args.uv_map.lower() == "auto" else args.uv_map,
                          filepath="" if to_colors else str(Path(os.path.abspath(args.out))),
                          source_path=str(source),
                          high_poly=high_poly, cage=cage,
                          bent_filepath=str(Path(os.path.abspath(args.bent_normal_out))) if args.bent_normal_out else "",
                          bent_space=args.bent_space, bent_convention=args.bent_convention,
                          wire_material=gltf_out is not None,
                          extra_inputs=reads + list(getattr(args, "batch_inputs", [])),
                          extra_outputs=writes, claimed=list(getattr(args, "batch_outputs", [])),
                          file_text={BAKE_KEY: key})
    job = BakeJob(request, bpy.context.evaluated_depsgraph_get)  # validates; refuses unwritable outputs
    skip_lines = []
    if args.skip_existing:  # checked after the validation: a run that would be refused is, finished or not
        left, skip_lines = skip_finished(request, key, report)
        if left is None:
            return skip_lines
        if left is not request:  # the frames still missing
            request = left
            job = BakeJob(request, bpy.context.evaluated_depsgraph_get)
    start_gpu()
    t0 = time.perf_counter()
    try:
        with report.phase("bake"):
            for fraction, text in job.steps():
                progress.update(text.split(":")[0], fraction if fraction > 0 else None)
        check_signals()  # never commit a run that was asked to stop
        if gltf_out is not None and any(result.tiles for _o, _u, result in job.results):
            raise CLIError("--gltf-out: glTF has no UDIM tiles, and the UVs baked lie on several; bake without "
                           "--gltf-out")
        with report.phase("write"):
            job.commit(hold=True)  # all or nothing with the mesh files below: a failure puts back the maps
            if mesh_out is not None:
                export_mesh_file(targets, mesh_out, colors=True)
            if gltf_out is not None:
                export_glb(targets, gltf_out)
            job.release()
    except BaseException:
        job.cancel()
        _report_frames(job, report)  # a sequence's finished frames stay, and are listed
        report.kept = job.written_note()
        raise
    report.timings["unwrap"] = round(job.unwrap_seconds, 4)
    for obj, uv_name, result in job.results:
        st = result.stats
        report.objects.append(dict(name=obj.name, triangles=st["target_faces"],
                                   uv_map=uv_name, uv_map_created=any(n == uv_name for _m, n in job.created_uv),
                                   covered_texels=st["covered_texels"], method=st["method"],
                                   smooth_corners=st["smooth_corners"],
                                   **({"texture_set": True} if args.texture_set else {}),
                                   **({"missed_texels": st["missed_texels"]} if "missed_texels" in st else {}),
                                   **({"udim_tiles": list(result.tiles)} if result.tiles else {})))
    lines = skip_lines
    for obj, label, result in job.baked():
        st = result.stats
        tile_files = job.files.get((label, "ao"), [])
        if not request.frames:  # a sequence's files are listed frame by frame (_report_frames)
            report.outputs.extend(tile_files if len(tile_files) > 1 else [output_path_for(request, obj)])
            report.outputs.extend(job.files.get((label, "bent"), []))
        report.warnings.extend(st.get("warnings", []))
        uv_name = next(uv for o, uv, _r in job.results if o == obj)
        where = (f"per {'vertex' if settings.color_domain == 'point' else 'face corner'} into colour attribute "
                 f"'{AO_ATTRIBUTE}')" if to_colors else f"UV map '{uv_name}') {settings.size}x{settings.size}")
        frames, dest = "", str(mesh_out) if to_colors else ", ".join(tile_files) or output_path_for(request, obj)
        if request.frames:
            reused = sum(e["reused"] for e in job.frame_results)
            frames = f" x {len(request.frames)} frames ({reused} reused, same geometry)"
            dest = frame_pattern(output_path_for(request, obj))
        lines.append(f"hao: baked '{label}' ({st['target_faces']} triangles, {where}, {settings.directions} "
                     f"directions{frames} in {time.perf_counter() - t0:.2f} s -> {dest}")
    if gltf_out is not None:
        report.outputs.append(str(gltf_out))
    if request.frames:
        _report_frames(job, report)
    return lines


def _report_frames(job, report: Report) -> None:
    """A sequence's frames in the report, in frame order: those baked (all, or the finished
    ones of a failed or interrupted run: they stay on disk) beside those --skip-existing
    found current; outputs lists every frame's files."""
    baked = [dict(frame=e["frame"], seconds=e["seconds"], reused=e["reused"], outputs=e["outputs"])
             for e in job.frame_results]
    report.frames = sorted(report.frames + baked, key=lambda entry: entry["frame"])
    report.outputs.extend(path for entry in report.frames for path in entry["outputs"])


def _bake_files(args, source: Path, mesh_out: Path | None, gltf_out: Path | None
                ) -> tuple[list[tuple[str, str]], list[tuple[str, str]]]:
    """(what the bake reads, what it writes besides its maps), as (path, what) pairs for
    core/output_files.py: the input and --high-poly files; the report, --gltf-out and a
    colour bake's mesh file."""
    reads = [(str(source), "the input file")]
    reads += [(spec, f"the high-poly file '{spec}'") for spec in args.high_poly or ()
              if Path(spec).suffix.lower() in INPUT_FORMATS and Path(spec).is_file()]
    writes = [(args.json or "", REPORT)]
    if mesh_out is not None:
        writes.append((str(mesh_out), "the mesh file (--out)"))
    if gltf_out is not None:
        writes.append((str(gltf_out), GLTF_OUT))
    return reads, writes


def _image_outputs(args, to_colors: bool) -> list[tuple[str, str]]:
    """The image files named on the command line (patterns, tokens unfilled)."""
    if to_colors:
        return []
    return [(args.out, "the AO map (--out)"), (args.bent_normal_out or "", "the bent normals (--bent-normal-out)")]


def _has_token(path: str) -> bool:
    from .core.bake.udim import UDIM_TOKEN
    return any(token in path for token in (OBJECT_TOKEN, FRAME_TOKEN, UDIM_TOKEN))


def run_render_ao(args, report: Report, progress: Progress) -> list[str]:
    import bpy

    from .core.imageio import check_writable, write_ao_file
    from .core.hao.view_settings import RenderSize, ViewAOSettings
    from .render_ao import render_camera_ao

    size = _validated(settings_from_args(args, RenderSize), RenderSize)
    settings = _validated(settings_from_args(args, ViewAOSettings), ViewAOSettings)
    if args.spheres < 0:
        raise CLIError(f"--spheres must be 0 or a positive count, got {args.spheres}")
    report.settings = {**asdict(size), **asdict(settings), "frame": args.frame, "spheres": args.spheres}
    source = check_input(Path(args.input), INPUT_FORMATS)
    report.input = str(source)
    out = check_writable(args.out, size.width, size.height, 4, source=source)
    check_json_target(args.json)
    check_output_files([(str(out), "the AO image (--out)"), (args.json or "", REPORT)],
                       [(str(source), "the input file")])
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
        from .blender.sphere_proxies import has_armature, make_proxies
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


def start_gpu() -> None:
    """Blender's GPU context, made while signals wait (an interrupt inside its creation, which
    runs Python callbacks from C, is not safe)."""
    from .blender.gpu_context import ensure_gpu_context
    with deferred_signals():
        ensure_gpu_context()


def _validated(settings, settings_cls):
    """settings.validated(), naming the option in the message."""
    try:
        return settings.validated()
    except SettingError as exc:
        option = option_for(settings_cls, exc.name)
        raise CLIError(f"{exc} ({option})" if option else str(exc)) from None


def run_bake_command(args, report: Report, progress: Progress) -> list[str]:
    """`bake`: one input with --out, or a batch (--out-dir, or several inputs), or a farm
    task's chunk of a manifest (--manifest, --chunk)."""
    if args.manifest:
        from .cli_farm import take_manifest_chunk
        take_manifest_chunk(args)
    if not args.input:
        raise CLIError("bake needs an INPUT file (or --manifest FILE)")
    if args.frames:
        parse_frames(args.frames)  # refused before any input is loaded
    if args.out_dir is None and len(args.input) == 1:
        if not args.out:
            raise CLIError("bake needs --out FILE (or --out-dir DIR)")
        _fill_input_token(args, args.input[0])
        args.input = args.input[0]
        return run_bake(args, report, progress)
    return run_batch(args, report, progress)


def _fill_input_token(args, path: str) -> None:
    """{input} in the output options becomes the input's cleaned name (input_file_name)."""
    from .blender.paths import input_file_name
    name = input_file_name(path)
    for option in ("out", "bent_normal_out", "gltf_out"):
        value = getattr(args, option)
        if value:
            setattr(args, option, value.replace(INPUT_TOKEN, name))


def _to_colors(args) -> bool:
    return getattr(args, "target", None) == "color-attribute"


def run_batch(args, report: Report, progress: Progress) -> list[str]:
    """Bake every input in this process (the GPU context, compiled shaders and caches carry
    over), each into --out-dir; a failed input is reported and the next one baked. A signal
    stops the batch at once. Returns the summary lines; report.inputs holds one report each."""
    if args.out_dir is None:
        raise CLIError("several inputs make a batch: give --out-dir DIR for their files")
    folder = Path(os.path.abspath(args.out_dir))
    if not folder.is_dir() or not os.access(folder, os.W_OK):
        raise CLIError(f"--out-dir '{args.out_dir}' does not exist or is not writable")
    template = args.out or BATCH_NAME
    if os.path.dirname(template):
        raise CLIError(f"with --out-dir, --out is a file name in it, not a path: '{template}'")
    if INPUT_TOKEN not in template and OBJECT_TOKEN not in template and len(args.input) > 1:
        raise CLIError(f"--out '{template}' would write every input's map to the same file: put {INPUT_TOKEN} in it")
    from .gpu.shaders import cached_shader_count
    subs = []
    for path in args.input:
        sub = argparse.Namespace(**vars(args))
        sub.out = str(folder / template)
        _fill_input_token(sub, path)
        sub.input = path
        subs.append(sub)
    # Every input's files at once, before any bake: two inputs named alike in different folders
    # ('a/x.obj', 'b/x.obj') would write one file. Names from {object} are checked per input,
    # against what the inputs before it wrote (batch_outputs).
    reads = [(os.path.abspath(path), f"input '{path}'") for path in args.input]
    planned = [(args.json or "", REPORT)]
    for sub in subs:
        planned += [(p, f"{what} of input '{sub.input}'") for p, what in _image_outputs(sub, _to_colors(sub))
                    + [(sub.gltf_out or "", GLTF_OUT)] if not _has_token(p)]
    check_output_files(planned, reads)
    lines, written = [], []
    for index, sub in enumerate(subs):
        path = sub.input
        progress.share(index, len(subs))
        one = Report(command="bake", input=str(path), hao=report.hao, blender=report.blender)
        started, shaders = time.perf_counter(), cached_shader_count()
        sub.batch_inputs = [entry for entry in reads if entry[1] != f"input '{path}'"]
        sub.batch_outputs = list(written)
        try:
            lines += run_bake(sub, one, progress)
            one.mark_done()
        except (KeyboardInterrupt, Terminated):
            raise
        except BaseException as exc:  # noqa: BLE001 - one input's failure is its line, the batch goes on
            code, message = _failure(exc, None)
            one.status, one.exit_code, one.error = "error", code, message
            report.input_errors.append(f"{path}: {message}")
        one.timings["total"] = round(time.perf_counter() - started, 4)
        one.shaders_compiled = cached_shader_count() - shaders
        report.inputs.append(one.as_dict())
        report.outputs.extend(one.outputs)
        written += [(out, f"an output of input '{path}'") for out in one.outputs]
        report.warnings.extend(f"{path}: {w}" for w in one.warnings)
    return lines


def run_farm_command(args, report: Report, progress: Progress) -> list[str]:
    from .cli_farm import run_farm
    return run_farm(args, report, progress)


COMMANDS = {"bake": run_bake_command, "render-ao": run_render_ao, "farm": run_farm_command}


def _needs_blender(args) -> bool:
    """Whether the command loads Blender (writing a farm job does not: 10,000 inputs in seconds)."""
    return args.command != "farm" or args.farm_command == "verify"


# -- entry point ------------------------------------------------------------------------------------

def main(argv: list[str] | None = None) -> int:
    argv = list(sys.argv[1:] if argv is None else argv)
    started = time.perf_counter()
    with ProcessOutput() as io, signals_as_exceptions():
        report = Report(command=argv[0] if argv else "", hao=__version__)
        args = None
        try:
            args = _parse(argv, io)
            if _needs_blender(args):
                with deferred_signals():
                    import bpy
                report.blender = bpy.app.version_string
            if getattr(args, "progress", "") == "openjd":  # a farm task: its progress for the farm
                progress = OpenJDProgress(io.out)
            else:
                progress = Progress(io.err, enabled=io.err_is_terminal and not args.quiet)
            try:
                lines = COMMANDS[args.command](args, report, progress)
            finally:
                progress.finish()
            if not args.quiet:
                for warning in report.warnings:
                    io.err.write(f"hao: warning: {warning}\n")
                if args.json != "-":
                    io.out.write("".join(line + "\n" for line in lines))
            for failed in report.input_errors:  # a batch's failed inputs, one line each
                io.err.write(f"hao: error: {failed}\n")
            code = EXIT_FAILURE if report.input_errors else EXIT_OK
            if report.input_errors:
                report.status = "partial"
                report.error = f"{len(report.input_errors)} of {len(report.inputs)} inputs failed"
            else:
                report.mark_done()
        except SystemExit as exc:  # --help / --version
            return int(exc.code or 0)
        except BaseException as exc:  # noqa: BLE001 - every failure becomes one line and an exit code
            code, message = _failure(exc, io)
            if report.inputs and code in EXIT_INTERRUPTED.values():  # a batch: the inputs before stay baked
                message = message.replace("nothing was written", f"the {len(report.inputs)} inputs before it are "
                                                                 f"written, nothing of the one it stopped")
            elif report.kept:  # a sequence: its finished frames stay (listed in the report)
                message = (message.replace("nothing was written", f"{report.kept}, nothing of the frame it stopped")
                           if code in EXIT_INTERRUPTED.values() else f"{message} ({report.kept})")
            report.status, report.error = ("interrupted" if code in EXIT_INTERRUPTED.values() else "error"), message
            io.err.write(f"hao: error: {message}\n")
            if isinstance(exc, OutputCollision) and REPORT in exc.parties:
                args.json = None  # its file is an input or another output: leave it alone
        report.exit_code = code
        report.timings["total"] = round(time.perf_counter() - started, 4)
        if args is not None and args.json:
            _write_report(report, args.json, io)
        return code


# Options whose value may start with '-' (argparse takes '-5-10' for an option otherwise).
DASH_VALUE_OPTIONS = ("--frames",)


def _parse(argv: list[str], io: ProcessOutput) -> argparse.Namespace:
    """parse_args with --help and --version written to the real stdout."""
    saved = sys.stdout, sys.stderr
    sys.stdout, sys.stderr = io.out, io.err
    joined = []
    for arg in argv:  # '--frames -5-10' as '--frames=-5-10'
        if joined and joined[-1] in DASH_VALUE_OPTIONS and re.match(r"-\d", arg):
            arg = f"{joined.pop()}={arg}"
        joined.append(arg)
    try:
        return build_parser().parse_args(joined)
    finally:
        sys.stdout, sys.stderr = saved


def _failure(exc: BaseException, io: ProcessOutput | None) -> tuple[int, str]:
    """(exit code, one-line message) for any exception (io: where HAO_DEBUG writes the
    traceback; None for a batch input's failure, which carries on)."""
    import signal

    if pending_signal() is not None and not isinstance(exc, (KeyboardInterrupt, Terminated)):
        exc = Terminated() if pending_signal() == signal.SIGTERM else KeyboardInterrupt()
    if isinstance(exc, KeyboardInterrupt):
        return EXIT_INTERRUPTED[signal.SIGINT], "interrupted (SIGINT): nothing was written"
    if isinstance(exc, Terminated):
        return EXIT_INTERRUPTED[signal.SIGTERM], "terminated (SIGTERM): nothing was written"
    if isinstance(exc, CLIError):
        return exc.code, str(exc)
    try:
        from .blender.gpu_context import GPUUnavailableError
    except ImportError:  # no bpy at all
        GPUUnavailableError = ()  # noqa: N806
    if GPUUnavailableError and isinstance(exc, GPUUnavailableError):
        return EXIT_NO_GPU, _last_line(exc)
    if isinstance(exc, (BakeInputError, OSError)):  # UnwrapError and SettingError included
        return EXIT_BAD_INPUT, _last_line(exc)
    if os.environ.get(DEBUG_ENV) and io is not None:
        io.err.write(io.log() + "".join(traceback.format_exception(exc)))
    return EXIT_FAILURE, (f"internal error ({type(exc).__name__}: {_last_line(exc)}); "
                          f"run with {DEBUG_ENV}=1 for details")


def _write_report(report: Report, target: str, io: ProcessOutput) -> None:
    text = report.to_json()
    if target == "-":
        io.out.write(text)
        return
    try:
        check_json_target(target)
    except CLIError:
        return  # that was the error already reported
    from .core.imageio import atomic_write_bytes
    try:
        atomic_write_bytes(Path(os.path.abspath(target)), text.encode())
    except OSError as exc:
        io.err.write(f"hao: error: cannot write the report '{target}': {exc.strerror or exc}\n")
