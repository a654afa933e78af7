# SPDX-License-Identifier: GPL-3.0-or-later
"""``hao farm openjd|flamenco|opencue INPUT... --out-dir DIR --bundle DIR [bake options]``:
a bake job in a farm's own format, every task the workstation's ``bake`` over one chunk
of the job's manifest; ``hao farm verify``: a job's check that every output exists.

Writing a job loads no mesh and no Blender (10,000 inputs take seconds); the bake options
given reach every task unchanged (forwarded_options).
"""
from __future__ import annotations

import argparse
import json
import os
import sys
from pathlib import Path

from .. import __version__
from .farm_formats import FARM_OWN, FORMATS, Job
from .io import Report
from ..core.farm.manifest import Manifest, make_manifest, read_manifest
from ..core.imageio import atomic_write_bytes


def forwarded_options(args: argparse.Namespace) -> list[str]:
    """The bake options given (those not at their defaults, and not farm's own), as
    '--option=value' (a value may start with '-'), flags alone, repeatable ones repeated."""
    from .parser import add_bake_arguments

    bake = argparse.ArgumentParser(add_help=False)
    add_bake_arguments(bake)
    out = []
    for action in bake._actions:  # noqa: SLF001 - argparse keeps its options there
        if not action.option_strings or action.dest in FARM_OWN:
            continue
        value = getattr(args, action.dest, action.default)
        if value == action.default:
            continue
        option = action.option_strings[-1]
        if isinstance(action, argparse._StoreTrueAction):  # noqa: SLF001
            out.append(option)
        elif isinstance(action, argparse._AppendAction):  # noqa: SLF001
            out += [f"{option}={_absolute_if_file(v)}" for v in value]
        else:
            out.append(f"{option}={value}")
    return out


def _absolute_if_file(value: str) -> str:
    """A --high-poly file as an absolute path (a task runs in the farm's own folder)."""
    return os.path.abspath(value) if Path(value).is_file() else value


def run_farm(args, report: Report, progress) -> list[str]:
    if args.farm_command == "verify":
        return run_verify(args, report)
    from .errors import CLIError
    from .parser import BATCH_NAME, INPUT_FORMATS
    from .scene import check_input
    if not args.input:
        raise CLIError(f"farm {args.farm_command} needs the INPUT files of the job")
    if not args.out_dir:
        raise CLIError(f"farm {args.farm_command} needs --out-dir DIR: where the tasks write the maps")
    template = args.out or BATCH_NAME
    if os.path.dirname(template):
        raise CLIError(f"with --out-dir, --out is a file name in it, not a path: '{template}'")
    _check_farm_outputs(args)
    from .bake import checked_options
    checked_options(_with_out(args, template))  # every bake option, as a task would check it
    for path in args.input:
        check_input(Path(path), INPUT_FORMATS)
    outputs = job_outputs(args, template)
    manifest = make_manifest(args.input, args.chunk_size, template, args.frames or "", outputs)
    _check_collisions(args, template)
    options = forwarded_options(args)
    bundle = Path(os.path.abspath(args.bundle))
    executable = args.executable or ("blender" if args.runner == "blender" else sys.executable)
    values = {"input_root": manifest.root, "out_dir": os.path.abspath(args.out_dir),
              "manifest": str(bundle / "manifest.json"), "executable": executable}
    if args.runner == "python":
        values["addon"] = os.path.abspath(args.addon_path)
    extra = [os.path.abspath(v) for v in args.high_poly or () if Path(v).is_file()]
    _check_job_text(args.farm_command, manifest, options, values, args.name)
    job = Job(manifest, args.runner, options, values, args.name, extra)
    files = {"manifest.json": manifest.to_json(), **FORMATS[args.farm_command][1](job)}
    bundle.mkdir(parents=True, exist_ok=True)
    for name, text in files.items():
        atomic_write_bytes(bundle / name, text.encode())
    report.outputs += [str(bundle / name) for name in files]
    report.settings = {"format": args.farm_command, "runner": args.runner, "chunk_size": args.chunk_size,
                       "tasks": manifest.chunk_count, "bake_options": options, "hao": __version__}
    return [f"hao: wrote the {args.farm_command} job of {len(manifest.entries)} inputs"
            + (f" (frames {manifest.frames})" if manifest.frames else "")
            + f" in {manifest.chunk_count} tasks -> {bundle}"]


def _with_out(args, template: str) -> argparse.Namespace:
    """A copy of the options with --out as a task fills it (its maps named after it)."""
    copy = argparse.Namespace(**vars(args))
    copy.out = template
    return copy


def _check_farm_outputs(args) -> None:
    """Every file a task writes lands in --out-dir: the extra outputs are names (or relative
    paths) in it, never absolute and never above it (a task's own folder is the farm's
    scratch space, deleted after the task)."""
    from .errors import CLIError
    from .parser import EXTRA_OUTPUT_OPTIONS
    for option in EXTRA_OUTPUT_OPTIONS:
        value = getattr(args, option, "") or ""
        if value and (os.path.isabs(value) or ".." in Path(value).parts):
            flag = "--" + option.replace("_", "-")
            raise CLIError(f"in a farm job, {flag} is a file name in --out-dir (the tasks write every output "
                           f"there), not '{value}'")


def job_outputs(args, template: str) -> tuple[str, ...]:
    """The file names (templates, '{input}' unfilled) a task writes per input in the
    output folder: --out, then each map of --maps and each extra output option."""
    from .bake import fill_map_outputs
    from .parser import EXTRA_OUTPUT_OPTIONS
    names = argparse.Namespace(**vars(args))
    names.out = template
    fill_map_outputs(names)
    return (template, *(getattr(names, option) for option in EXTRA_OUTPUT_OPTIONS if getattr(names, option, "")))


def _check_collisions(args, template: str) -> None:
    """The batch's own check over the whole job, before anything is written: two inputs
    whose files would land on one name (same file name in two folders, names that clean
    to one, an --out without {input}) are refused here, not found overwritten on the farm."""
    from .batch import batch_plan
    batch_plan(args, Path(os.path.abspath(args.out_dir)), template)


def _check_job_text(farm: str, manifest: Manifest, options: list[str], values: dict, name: str) -> None:
    """What a farm parses: no control character anywhere (a newline splits a cuecmd line
    into two commands), and no '{{' or '}}' in what an OpenJD template holds (its format
    strings' own delimiters; paths travel as parameter values, never parsed)."""
    from .errors import CLIError
    from ..core.farm.manifest import text_fault
    texts = [("an input path", manifest.root + "/" + entry) for entry in manifest.entries]
    texts += [("--out", manifest.out), ("--name", name)] + [("a bake option", option) for option in options]
    names = {"input_root": "the input folder", "out_dir": "--out-dir", "manifest": "--bundle",
             "executable": "--executable", "addon": "--addon-path"}
    texts += [(names[key], value) for key, value in values.items()]
    for what, text in texts:
        fault = text_fault(text)
        if fault:
            raise CLIError(f"{what} {fault}: {json.dumps(text)[:80]}; a farm's command line cannot carry it")
    if farm == "openjd":
        for what, text in [("--name", name)] + [("a bake option", option) for option in options]:
            if "{{" in text or "}}" in text:
                raise CLIError(f"{what} holds '{{{{' or '}}}}', which Open Job Description reads as its own "
                               f"format string: {json.dumps(text)[:80]}")


def take_manifest_chunk(args) -> None:
    """A farm task's bake: its chunk's inputs (under --input-root, else the manifest's
    root), the manifest's output name, the chunk's frames; --out-dir is required (made
    when a file is written)."""
    from .errors import CLIError
    if args.input:
        raise CLIError("--manifest names the inputs: give no INPUT besides it")
    if not args.out_dir:
        raise CLIError("--manifest needs --out-dir DIR")
    if args.chunk is None:
        raise CLIError("--manifest needs --chunk N: the task's chunk of the job")
    if args.out:
        raise CLIError("--manifest names the output files: give no --out besides it")
    if args.frames:
        raise CLIError("--manifest names the frames of each chunk: give no --frames besides it")
    manifest = read_manifest(args.manifest)
    root = args.input_root or manifest.root
    args.input = [os.path.join(root, *entry.split("/")) for entry in manifest.chunk_inputs(args.chunk)]
    args.out = manifest.out
    args.frames = manifest.chunk_frames(args.chunk) or None
    # The output folder is made as the first file is written (a task that fails leaves none).


def check_chunk_without_manifest(args) -> None:
    from .errors import CLIError
    if args.chunk is not None or args.input_root:
        raise CLIError("--chunk and --input-root belong to a farm task's --manifest: give --manifest FILE")


def expected_outputs(manifest: Manifest, entry: str) -> list[tuple[int | None, str]]:
    """(frame or None, file name in the output folder) of every file the Bake step writes
    for one input: each of manifest.outputs, '{input}' filled, per frame; '{object}' and
    UDIM tiles stay as tokens (the task's receipt names those files)."""
    from ..core.output_files import input_file_name
    from ..core.frame_ranges import parse_frames
    from ..core.output_files import FRAME_TOKEN, INPUT_TOKEN, frame_file, with_token
    frames = parse_frames(manifest.frames) if manifest.frames else [None]
    out = []
    for template in manifest.outputs:
        name = template.replace(INPUT_TOKEN, input_file_name(entry))
        if manifest.frames:
            name = with_token(name, FRAME_TOKEN)  # as the bake names a sequence's files
        out += [(frame, name if frame is None else frame_file(name, frame)) for frame in frames]
    return out


def _name_pattern(name: str):
    """A regular expression of the files one expected name stands for: '{object}' any
    name, a UDIM tile's number before the extension, and '_NAME' added before it where
    an input held several meshes (as the bake names them)."""
    import re

    from ..core.bake.udim import UDIM_TOKEN
    from ..core.output_files import OBJECT_TOKEN
    stem, ext = os.path.splitext(name)
    parts = re.escape(stem).replace(re.escape(OBJECT_TOKEN), ".+").replace(re.escape(UDIM_TOKEN), r"\d{4}")
    several = "" if OBJECT_TOKEN in stem else "(_.+)?"
    return re.compile(f"{parts}{several}(\\.\\d{{4}})?{re.escape(ext)}", re.IGNORECASE)


def _owners(names: list[str], recorded: list[str]) -> dict[str, list[str]]:
    """{expected name: the recorded files it stands for}: each file goes to the one name
    whose pattern matches it with the most literal characters ('b_{object}_thickness.png'
    over 'b_{object}.png' for 'b_b_thickness.png')."""
    from ..core.bake.udim import UDIM_TOKEN
    from ..core.output_files import OBJECT_TOKEN
    patterns = [(len(n.replace(OBJECT_TOKEN, "").replace(UDIM_TOKEN, "")), n, _name_pattern(n)) for n in names]
    owned: dict[str, list[str]] = {}
    for file in recorded:
        matches = [(literal, name) for literal, name, pattern in patterns if pattern.fullmatch(file)]
        if matches:
            owned.setdefault(max(matches)[1], []).append(file)
    return owned


def receipts(manifest: Manifest, out_dir: str) -> dict[str, list[str]]:
    """{manifest entry: the files its task's receipt says it wrote (or kept), for the
    entries whose bake finished}, from every chunk's report in the output folder."""
    written: dict[str, list[str]] = {}
    for chunk in range(manifest.chunk_count):
        path = os.path.join(out_dir, *manifest.receipt(chunk).split("/"))
        try:
            data = json.loads(Path(path).read_text(encoding="utf-8"))
            inputs = data["inputs"]
        except (OSError, ValueError, KeyError, TypeError):
            continue
        for entry, one in zip(manifest.chunk_inputs(chunk), inputs if isinstance(inputs, list) else []):
            if isinstance(one, dict) and one.get("exit_code") == 0 and isinstance(one.get("outputs"), list):
                written.setdefault(entry, []).extend(os.path.basename(str(f)) for f in one["outputs"])
    return written


def run_verify(args, report: Report) -> list[str]:
    """Exit 1 naming the expected outputs that are missing, empty or broken: every file of
    every input (each map of the job, each frame), by its exact name where the manifest
    gives it, else (an '{object}' name, UDIM tiles) as the input's own task recorded it;
    every file must decode in full."""
    from .errors import EXIT_FAILURE, CLIError
    from ..core.file_checks import output_is_whole
    manifest = read_manifest(args.manifest)
    out_dir = os.path.abspath(args.out_dir)
    written = receipts(manifest, out_dir)
    missing, found, count = [], [], 0
    for entry in manifest.entries:
        recorded = written.get(entry, [])
        names = [name for _frame, name in expected_outputs(manifest, entry)]
        owned = _owners(names, recorded)
        for name in names:
            count += 1
            exact = os.path.join(out_dir, name)
            files = [exact] if name in recorded or (not recorded and os.path.isfile(exact)) else \
                [os.path.join(out_dir, f) for f in owned.get(name, [])]
            if not files or not all(output_is_whole(f) for f in files):
                missing.append(name)
            found += files
    report.outputs += sorted(set(found))
    if missing:
        shown = ", ".join(missing[:10]) + (" ..." if len(missing) > 10 else "")
        raise CLIError(f"{len(missing)} of {count} expected outputs are missing, empty or broken: {shown}",
                       code=EXIT_FAILURE)
    return [f"hao: verified {len(set(found))} outputs of {len(manifest.entries)} inputs in {args.out_dir}"]
