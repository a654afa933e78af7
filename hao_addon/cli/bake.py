# SPDX-License-Identifier: GPL-3.0-or-later
"""`bake` of one input: check, load, bake, write all or nothing, report."""
from __future__ import annotations

import os
import time
from dataclasses import asdict, dataclass, replace
from pathlib import Path

from .errors import CLIError
from .io import check_signals, deferred_signals, load_blender, Progress, REPORT, Report
from .options import option_for, settings_from_args
from .parser import EXTRA_OUTPUT_OPTIONS, IMAGE_OPTIONS, INPUT_FORMATS
from .scene import (check_gltf_target, check_input, check_json_target, check_mesh_target, export_glb,
                        export_mesh_file, load_scene, MESH_OUT_FORMATS, pick_high_poly, pick_mesh, pick_target,
                        uv_mesh_path)
from ..core.bake.map_kinds import EXTRA_MAPS, MAP_KINDS
from ..core.bake.target_kinds import target_kind
from ..core.frame_ranges import parse_frames
from ..core.output_files import check_output_files, FRAME_TOKEN, INPUT_TOKEN, OBJECT_TOKEN
from ..core.setting_spec import SettingError


GLTF_OUT = "the glTF file (--gltf-out)"  # its name in collision messages


@dataclass
class _Run:
    """One input's bake as checked before anything is loaded."""

    settings: object  # BakeSettings
    options: object   # JobOptions
    source: Path
    frames: list[int] | None
    gltf_out: Path | None
    mesh_out: Path | None  # a colour bake's mesh file
    reads: list[tuple[str, str]]
    writes: list[tuple[str, str]]
    key: str  # the run's bake key (skip.run_key), once the scene is loaded (_scene_key)

    @property
    def to_colors(self) -> bool:
        """The bake writes one value per mesh element (a colour attribute), no image."""
        return not target_kind(self.settings.target).writes_images


def run_bake(args, report: Report, progress: Progress) -> list[str]:
    """Bake one input (args.input): check every file, load, pick the meshes, bake, write all
    or nothing; returns the summary lines to print."""
    run = _checked_run(args, report)
    bpy = load_blender(report)
    from ..blender.bake_job import BakeJob
    with report.phase("load"):
        progress.update("loading")
        load_scene(run.source)
    check_signals()
    run.key = _scene_key(args, run)
    groups = _pick_groups(args, run, report) if run.options.match_names else None
    if groups is not None:
        targets, high_poly, cage = [low for group in groups for low in group.lows], None, None
    else:
        targets, high_poly, cage = _pick_objects(args, report)
    request = _request(args, run, targets, high_poly, cage, groups)
    job = BakeJob(request, bpy.context.evaluated_depsgraph_get)  # validates; refuses unwritable outputs
    skip_lines = []
    if args.skip_existing:  # checked after the validation: a run that would be refused is, finished or not
        from .skip import skip_finished
        left, skip_lines = skip_finished(request, run.key, report)
        if left is None:
            return report.notes + skip_lines
        if left is not request:  # the frames still missing
            request = left
            job = BakeJob(request, bpy.context.evaluated_depsgraph_get)
    start_gpu()
    t0 = time.perf_counter()
    uv_meshes = _bake_and_write(job, run, targets, report, progress)
    return report.notes + skip_lines + _report_results(job, run, args, report, time.perf_counter() - t0, uv_meshes)


def _checked_run(args, report: Report) -> _Run:
    """The settings, and every file the run reads and writes, checked before a long load."""
    from ..core.output_files import example_path
    from ..core.imageio import check_writable

    settings, options, frames = checked_options(args)
    source = check_input(Path(args.input), INPUT_FORMATS)
    first_frame = frames[0] if frames else 0
    if source.suffix.lower() != ".blend":  # imported objects carry no terminator offset of their own
        settings = replace(settings, terminator="setting")
    kind = target_kind(settings.target)
    to_colors = not kind.writes_images
    images = [row.option for row in EXTRA_MAPS if kind.name not in row.target_kinds]  # the maps its kind lacks
    if to_colors and (args.gltf_out or any(getattr(args, option) for option in images)):
        options = ", ".join("--" + option.replace("_", "-") for option in images)
        raise CLIError("--target color-attribute writes the mesh with its colour attribute to --out (.blend, .glb "
                       f"or .ply); {options} and --gltf-out are image bakes")
    for kind in EXTRA_MAPS:
        path = getattr(args, kind.option)
        if not path:
            continue
        if kind.setting:  # its file asks for it: --bent-normal-out turns Bent Normals on
            settings = replace(settings, **{kind.setting: True})
        check_writable(example_path(path, first_frame), settings.size, settings.size, kind.channels, source=source)
    gltf_out = check_gltf_target(args.gltf_out, source) if args.gltf_out else None
    report.settings = {**asdict(settings), "uv_map": args.uv_map, "occluders": args.occluders}
    report.input = str(source)
    # Refused before a long load; checked again with the object's name once it is known.
    mesh_out = check_mesh_target(args.out, source, MESH_OUT_FORMATS, "--out") if to_colors else None
    if not to_colors:
        check_writable(example_path(args.out, first_frame), settings.size, settings.size, 1, source=source)
    check_json_target(args.json)
    reads, writes = _bake_files(args, source, mesh_out, gltf_out)
    literal = [(path, what) for path, what in image_outputs(args, to_colors) if not has_token(path)]
    check_output_files(writes + literal, reads)  # again with every file once the objects are known (BakeJob)
    return _Run(settings, options, source, frames, gltf_out, mesh_out, reads, writes, key="")


def checked_options(args) -> tuple[object, object, list[int] | None]:
    """(BakeSettings, JobOptions, frames) of the options, each checked as a bake checks them
    before it loads anything; a farm job's writer runs the same checks (nothing is refused
    later, on the farm, that could have been refused at submission)."""
    from ..core.bake.job_options import JobOptions
    from ..core.bake.settings import BakeSettings
    fill_map_outputs(args)
    settings = validated(settings_from_args(args, BakeSettings), BakeSettings)
    options = validated(settings_from_args(args, JobOptions), JobOptions)
    frames = parse_frames(args.frames) if args.frames else None
    _check_image_options(args, options, frames)
    return settings, options, frames


def _check_image_options(args, options, frames) -> None:
    """Options that would be ignored where they do not apply are refused: PNG bits (and the
    dither) with no PNG output; one glTF file for a sequence of frames."""
    if frames and args.gltf_out:
        raise CLIError("--gltf-out writes one mesh with one set of maps, --frames a map per frame: bake the glTF "
                       "file of one frame without --frames")
    if str(options.png_bits) != "16" or options.dither:
        images = [args.out or ""] + [getattr(args, option) or "" for option in IMAGE_OPTIONS]
        if not any(path.lower().endswith(".png") for path in images):
            raise CLIError(f"--png-bits {options.png_bits}{' with --dither' if options.dither else ''} is for PNG "
                           f"files, and every output here is a 32-bit float EXR")


def _scene_key(args, run: _Run) -> str:
    """The run's bake key once the scene is loaded: its texture files count as inputs (an
    alpha texture edited on disk makes the maps stale)."""
    from ..blender.images import scene_image_files
    from .skip import run_key
    files = [Path(path) for path, _what in run.reads]
    files += [Path(path) for path, _what in scene_image_files() if os.path.isfile(path)]
    return run_key(args, files)


def fill_map_outputs(args) -> None:
    """--maps: each map without its own output option is written beside --out, named after
    it with _MAP before the extension."""
    from .parser import MAP_OUTPUTS

    names = [name.strip() for name in (getattr(args, "maps", "") or "").split(",") if name.strip()]
    unknown = [name for name in names if name not in MAP_OUTPUTS]
    if unknown:
        raise CLIError(f"--maps: unknown map '{unknown[0]}', expected some of {', '.join(MAP_OUTPUTS)}")
    for name in names:
        option = MAP_OUTPUTS[name]
        if option and not getattr(args, option) and args.out:
            stem, suffix = os.path.splitext(args.out)
            setattr(args, option, f"{stem}_{name.replace('-', '_')}{suffix}")


def _pick_objects(args, report: Report) -> tuple[list, list | None, object]:
    """(the meshes to bake, the Selected-to-Active high-poly or None, the cage or None) of
    the loaded input, as the options name them."""
    import bpy

    high_poly = pick_high_poly(args.high_poly) if args.high_poly else None
    cage = pick_mesh(args.cage, "--cage") if args.cage else None
    if cage is not None and high_poly is None:
        raise CLIError("--cage needs --high-poly (Selected to Active)")
    exclude = tuple(high_poly or ()) + ((cage,) if cage else ())
    if args.all_meshes:
        targets = [o for o in bpy.context.view_layer.objects
                   if o.type == 'MESH' and o not in exclude and o.visible_get()]
        if not targets:
            raise CLIError("the input contains no mesh object")
    else:
        picked = [pick_target(name, exclude, args.input.lower().endswith(".blend")) for name in (args.object or [""])]
        targets = [obj for obj, _why in picked]
        report.notes.extend(why for _obj, why in picked if why)
    if len({o.name for o in targets}) != len(targets):
        raise CLIError("--object names the same mesh twice")
    if args.texture_set and len(targets) < 2:
        raise CLIError("--texture-set bakes several meshes into one image: name them with --object (twice or more)")
    if high_poly is not None and len(targets) > 1:
        raise CLIError("Selected to Active bakes onto one low-poly: give one --object")
    if high_poly is not None:
        report.settings["high_poly"] = [o.name for o in high_poly]
        report.settings["cage"] = cage.name if cage else ""
    return targets, high_poly, cage


def _pick_groups(args, run: _Run, report: Report) -> list:
    """The bake groups of the loaded input's meshes, matched by name (--match-names); the
    names that matched nothing become warnings."""
    import bpy

    from ..blender.bake_groups import bake_groups

    for option, given in (("--object", args.object), ("--high-poly", args.high_poly), ("--cage", args.cage),
                          ("--all-meshes", args.all_meshes)):
        if given:
            raise CLIError(f"--match-names finds the meshes by name: {option} does not apply")
    groups, notes = bake_groups(list(bpy.context.view_layer.objects), run.options)
    if not groups:
        raise CLIError(f"--match-names: no mesh name (or collection) ends in '{run.options.low_suffix}' "
                       f"(meshes: {', '.join(o.name for o in bpy.context.view_layer.objects if o.type == 'MESH')})")
    report.warnings.extend(notes)
    report.settings["groups"] = {g.name: {"low": [o.name for o in g.lows], "high": [o.name for o in g.highs]}
                                 for g in groups}
    return groups


def _request(args, run: _Run, targets: list, high_poly: list | None, cage, groups: list | None = None):
    """The job's BakeRequest: what to bake, and every file the run reads and writes."""
    from ..blender.bake_request import BakeRequest
    from ..core.imageio import BAKE_KEY

    return BakeRequest(targets=targets, settings=run.settings, options=run.options, frames=run.frames,
                       uv_map="AUTO" if args.uv_map.lower() == "auto" else args.uv_map,
                       filepath="" if run.to_colors else str(Path(os.path.abspath(args.out))),
                       source_path=str(run.source), high_poly=high_poly, cage=cage, groups=groups,
                       map_paths={kind.key: str(Path(os.path.abspath(getattr(args, kind.option))))
                                  for kind in EXTRA_MAPS if getattr(args, kind.option)},
                       wire_material=run.gltf_out is not None,
                       extra_inputs=run.reads + list(getattr(args, "batch_inputs", [])),
                       extra_outputs=run.writes, claimed=list(getattr(args, "batch_outputs", [])),
                       file_text={BAKE_KEY: run.key})


def _bake_and_write(job, run: _Run, targets: list, report: Report, progress: Progress) -> list[tuple[str, Path]]:
    """Run the job, then write its maps and the mesh files all or nothing; on any failure or
    signal nothing of it is left but a sequence's finished frames (listed in the report).
    Returns the meshes written with the UV maps the bake made (_write_uv_meshes)."""
    try:
        with report.phase("bake"):
            for fraction, text in job.steps():
                progress.update(text.split(":")[0], fraction if fraction > 0 else None)
        check_signals()  # never commit a run that was asked to stop
        if run.gltf_out is not None and any(result.tiles for _o, _u, result in job.results):
            raise CLIError("--gltf-out: glTF has no UDIM tiles, and the UVs baked lie on several; bake without "
                           "--gltf-out")
        with report.phase("write"):
            job.commit(hold=True)  # all or nothing with the mesh files below: a failure puts back the maps
            if run.mesh_out is not None:
                export_mesh_file(targets, run.mesh_out, colors=True)
            if run.gltf_out is not None:
                export_glb(targets, run.gltf_out)
            uv_meshes = _write_uv_meshes(job, run, targets)
            job.release()
    except BaseException:
        job.cancel()
        _report_frames(job, report)  # a sequence's finished frames stay, and are listed
        report.kept = job.written_note()
        raise
    return uv_meshes


def _report_results(job, run: _Run, args, report: Report, seconds: float, uv_meshes: list = ()) -> list[str]:
    """The report's objects, outputs and warnings of a finished job; returns its summary lines."""
    from ..blender.bake_request import output_path_for
    from ..blender.color_attributes import AO_ATTRIBUTE
    from ..blender.mesh_data import AO_UV_NAME
    from ..core.output_files import frame_pattern

    request, settings = job.request, run.settings
    report.timings["unwrap"] = round(job.unwrap_seconds, 4)
    report.objects.extend(job.summary())
    lines = [f"hao: {note}" for note in job.unwrap_notes]  # an unwrap that fell back to xatlas' own charts
    for obj, label, result in job.baked():
        st = result.stats
        tile_files = job.files.get((label, "ao"), [])
        if not request.frames:  # a sequence's files are listed frame by frame (_report_frames)
            report.outputs.extend(tile_files if len(tile_files) > 1 else [output_path_for(request, obj)])
            for kind in EXTRA_MAPS:
                report.outputs.extend(job.files.get((label, kind.key), []))
        report.warnings.extend(st.get("warnings", []))
        uv_name = next(uv for o, uv, _r in job.results if o == obj)
        where = (f"per {'vertex' if settings.color_domain == 'point' else 'face corner'} into colour attribute "
                 f"'{AO_ATTRIBUTE}')" if run.to_colors else f"UV map '{uv_name}') {settings.size}x{settings.size}")
        dest = str(run.mesh_out) if run.to_colors else ", ".join(tile_files) or output_path_for(request, obj)
        dest = ", ".join([dest] + [path for kind in EXTRA_MAPS for path in job.files.get((label, kind.key), [])])
        frames = ""
        if request.frames:
            reused = sum(e["reused"] for e in job.frame_results)
            frames = f" x {len(request.frames)} frames ({reused} reused, same geometry)"
            dest = frame_pattern(output_path_for(request, obj))
        error = result.error.text() if result.error is not None else f"{settings.directions} directions"
        count = st.get("instanced_occluders", 0)
        instanced = f", {count} instanced occluder{'s' if count > 1 else ''}" if count else ""
        lines.append(f"hao: baked '{label}' ({st['target_faces']} triangles{instanced}, {where}, {error}{frames} in "
                     f"{seconds:.2f} s -> {dest}")
        if "rebake" in st:  # --rebake-changed: what it re-baked, and the bound on what it kept
            from ..rebake import RebakeReport
            lines.append(f"hao: '{label}' {RebakeReport(**st['rebake']).text()}")
    bound = run.options.verify_max_error
    for label, check in job.verifications:
        lines.append(f"hao: '{label}' {check.text()}")
        if bound > 0.0 and check.misses(bound):
            report.check_failures.append(f"'{label}': the verification puts the map's p99 error at {check.p99[1]:.2g} "
                                         f"(95 % from {check.p99[0]:.2g}), above --verify-max-error {bound:g}")
    if run.gltf_out is not None:
        report.outputs.append(str(run.gltf_out))
    for name, path in uv_meshes:
        report.outputs.append(str(path))
        lines.append(f"hao: '{name}' had no UV map: the mesh with the one baked into ('{AO_UV_NAME}') -> {path}")
    if request.frames:
        _report_frames(job, report)
    return lines


def _write_uv_meshes(job, run: _Run, targets: list) -> list[tuple[str, Path]]:
    """(object name, file) of each baked mesh whose UV map the bake made (it had none), written
    beside its map (scene.uv_mesh_path) so that the map can be applied: those UVs exist
    nowhere else once this process ends. Not where --gltf-out holds them already, nor for a
    sequence or a colour attribute."""
    from ..blender.bake_request import output_path_for
    if run.gltf_out is not None or run.to_colors or job.request.frames:
        return []
    made = {mesh.name for mesh, _name in job.created_uv}
    written = []
    try:
        for obj in targets:
            if obj.data.name in made:
                path = uv_mesh_path(output_path_for(job.request, obj), run.source)
                export_mesh_file([obj], path)
                written.append((obj.name, path))
    except BaseException:  # all or nothing: the maps are put back by the caller, these here
        for _name, path in written:
            path.unlink(missing_ok=True)
        raise
    return written


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


def image_outputs(args, to_colors: bool) -> list[tuple[str, str]]:
    """The image files named on the command line (patterns, tokens unfilled)."""
    if to_colors:
        return []
    return [(args.out if kind.key == "ao" else getattr(args, kind.option) or "", kind.what) for kind in MAP_KINDS]


def has_token(path: str) -> bool:
    from ..core.bake.udim import UDIM_TOKEN
    return any(token in path for token in (OBJECT_TOKEN, FRAME_TOKEN, UDIM_TOKEN))


def validated(settings, settings_cls):
    """settings.validated(), naming the option in the message."""
    try:
        return settings.validated()
    except SettingError as exc:
        option = option_for(settings_cls, exc.name)
        raise CLIError(f"{exc} ({option})" if option else str(exc)) from None


def fill_input_token(args, path: str) -> None:
    """{input} in the output options becomes the input's cleaned name (input_file_name)."""
    from ..core.output_files import input_file_name
    name = input_file_name(path)
    for option in ("out", *EXTRA_OUTPUT_OPTIONS):
        value = getattr(args, option)
        if value:
            setattr(args, option, value.replace(INPUT_TOKEN, name))


def to_colors(args) -> bool:
    """The command bakes one value per mesh element (--target color-attribute), no image."""
    target = getattr(args, "target", None)
    return target is not None and not target_kind(target).writes_images


def start_gpu() -> None:
    """Blender's GPU context, made while signals wait (an interrupt inside its creation, which
    runs Python callbacks from C, is not safe)."""
    from ..gpu.context import ensure_gpu_context
    with deferred_signals():
        ensure_gpu_context()
