# SPDX-License-Identifier: GPL-3.0-or-later
"""Command line: ``python -m hao_addon bake INPUT --out FILE ...`` and
``python -m hao_addon render-ao INPUT.blend --out FILE ...``.

The same entry point is registered as a Blender command (``blender -c hao bake ...``).
Exit codes: 0 done, 1 internal error, 2 bad arguments or input, 3 no usable GPU,
130 / 143 interrupted by SIGINT / SIGTERM. Every failure is one line on stderr,
``hao: error: <what>``, with nothing written; a successful ``--quiet`` run prints nothing.
"""
from __future__ import annotations

import os
import sys
import time
from pathlib import Path

from .. import __version__
from .bake import fill_input_token, run_bake
from .batch import run_batch
from .errors import CLIError, EXIT_FAILURE, EXIT_OK, failure
from .io import (EXIT_INTERRUPTED, OpenJDProgress, ProcessOutput, Progress, REPORT, Report,
                     signals_as_exceptions)
from .parser import parse
from .render import run_render_ao
from .scene import check_json_target
from ..core.frame_ranges import parse_frames
from ..core.output_files import OutputCollision


def run_bake_command(args, report: Report, progress: Progress) -> list[str]:
    """`bake`: one input with --out, or a batch (--out-dir, or several inputs), or a farm
    task's chunk of a manifest (--manifest, --chunk)."""
    from .farm import check_chunk_without_manifest, take_manifest_chunk
    if args.manifest:
        take_manifest_chunk(args)
    else:
        check_chunk_without_manifest(args)
    if not args.input:
        raise CLIError("bake needs an INPUT file (or --manifest FILE)")
    if args.frames:
        parse_frames(args.frames)  # refused before any input is loaded
    if args.out_dir is None and len(args.input) == 1:
        if not args.out:
            raise CLIError("bake needs --out FILE (or --out-dir DIR)")
        fill_input_token(args, args.input[0])
        args.input = args.input[0]
        return run_bake(args, report, progress)
    return run_batch(args, report, progress)


def run_farm_command(args, report: Report, progress: Progress) -> list[str]:
    from .farm import run_farm
    return run_farm(args, report, progress)


COMMANDS = {"bake": run_bake_command, "render-ao": run_render_ao, "farm": run_farm_command}


def main(argv: list[str] | None = None) -> int:
    argv = list(sys.argv[1:] if argv is None else argv)
    started = time.perf_counter()
    with ProcessOutput() as io, signals_as_exceptions():
        report = Report(command=argv[0] if argv else "", hao=__version__)
        args = None
        try:
            args = parse(argv, io)
            if getattr(args, "progress", "") == "openjd":  # a farm task: its progress for the farm
                progress = OpenJDProgress(io.out)
            else:
                progress = Progress(io.err, enabled=not args.quiet, terminal=io.err_is_terminal)
            try:
                lines = COMMANDS[args.command](args, report, progress)
            finally:
                progress.finish()
            if not args.quiet:
                for warning in report.warnings:
                    io.err.write(f"hao: warning: {warning}\n")
                if args.json != "-":
                    io.out.write("".join(line + "\n" for line in lines))
            for failed in report.input_errors + report.check_failures:  # one line each
                io.err.write(f"hao: error: {failed}\n")
            code = EXIT_FAILURE if report.input_errors or report.check_failures else EXIT_OK
            if report.input_errors:
                report.status = "partial"
                report.error = f"{len(report.input_errors)} of {len(report.inputs)} inputs failed"
            elif report.check_failures:
                report.status, report.error = "check-failed", "; ".join(report.check_failures)
            else:
                report.mark_done()
        except SystemExit as exc:  # --help / --version
            return int(exc.code or 0)
        except BaseException as exc:  # noqa: BLE001 - every failure becomes one line and an exit code
            code, message = failure(exc, io)
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
        if args is not None and args.json and not _makes_folders_for_nothing(args, report):
            _write_report(report, args.json, io)
        return code


def _makes_folders_for_nothing(args, report: Report) -> bool:
    """Whether the report is a farm task's receipt of a run that wrote nothing, into a folder
    that does not exist: a failed task leaves no folder behind (its error is on stderr)."""
    if not getattr(args, "manifest", None) or report.exit_code == 0 or report.outputs or args.json == "-":
        return False
    return not os.path.isdir(os.path.dirname(os.path.abspath(args.json)))


def _write_report(report: Report, target: str, io: ProcessOutput) -> None:
    text = report.to_json()
    if target == "-":
        io.out.write(text)
        return
    try:
        check_json_target(target)
    except CLIError:
        return  # that was the error already reported
    from ..core.imageio import atomic_write_bytes
    try:
        atomic_write_bytes(Path(os.path.abspath(target)), text.encode())
    except OSError as exc:
        io.err.write(f"hao: error: cannot write the report '{target}': {exc.strerror or exc}\n")
