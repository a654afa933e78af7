# SPDX-License-Identifier: GPL-3.0-or-later
"""`bake` of several inputs in one process (--out-dir)."""
from __future__ import annotations

import argparse
import os
import time
from pathlib import Path

from .bake import fill_input_token, GLTF_OUT, has_token, image_outputs, run_bake, to_colors
from .errors import CLIError, failure
from .io import load_blender, Progress, REPORT, Report, Terminated
from .parser import BATCH_NAME, EXTRA_OUTPUT_OPTIONS
from ..core.folders import nearest_existing, unmakeable_reason
from ..core.output_files import check_output_files, INPUT_TOKEN, OBJECT_TOKEN




def batch_plan(args, folder: Path, template: str) -> tuple[list[argparse.Namespace], list[tuple[str, str]]]:
    """(each input's own options: --out and the extra outputs filled and in `folder`; the
    files the batch reads), every input's files checked against every other's and the
    inputs before anything is baked: two inputs named alike in different folders ('a/x.obj',
    'b/x.obj') or names that clean to one ('b c', 'b_c') would write one file. Names from
    {object} are checked per input, against what the inputs before it wrote (batch_outputs)."""
    if INPUT_TOKEN not in template and OBJECT_TOKEN not in template and len(args.input) > 1:
        raise CLIError(f"--out '{template}' would write every input's map to the same file: put {INPUT_TOKEN} in it")
    subs = []
    for path in args.input:
        sub = argparse.Namespace(**vars(args))
        sub.out = str(folder / template)
        fill_input_token(sub, path)
        for option in EXTRA_OUTPUT_OPTIONS:  # relative: in --out-dir (a farm task's own folder is scratch)
            value = getattr(sub, option, "")
            if value and not os.path.isabs(value):
                setattr(sub, option, str(folder / value))
        sub.input = path
        subs.append(sub)
    reads = [(os.path.abspath(path), f"input '{path}'") for path in args.input]
    planned = [(args.json or "", REPORT)]
    for sub in subs:
        planned += [(p, f"{what} of input '{sub.input}'") for p, what in image_outputs(sub, to_colors(sub))
                    + [(sub.gltf_out or "", GLTF_OUT)] if not has_token(p)]
    check_output_files(planned, reads)
    return subs, reads


def run_batch(args, report: Report, progress: Progress) -> list[str]:
    """Bake every input in this process (the GPU context, compiled shaders and caches carry
    over), each into --out-dir; a failed input is reported and the next one baked. A signal
    stops the batch at once. Returns the summary lines; report.inputs holds one report each."""
    if args.out_dir is None:
        raise CLIError("several inputs make a batch: give --out-dir DIR for their files")
    folder = Path(os.path.abspath(args.out_dir))
    reason = unmakeable_reason(folder)
    if reason or not os.access(nearest_existing(folder), os.W_OK):
        raise CLIError(f"cannot make --out-dir '{args.out_dir}': {reason or 'permission denied'}")
    template = args.out or BATCH_NAME
    if os.path.dirname(template):
        raise CLIError(f"with --out-dir, --out is a file name in it, not a path: '{template}'")
    subs, reads = batch_plan(args, folder, template)
    load_blender(report)
    from ..gpu.shaders import cached_shader_count
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
            if one.check_failures:  # baked and written, but its verification failed
                one.status, one.exit_code, one.error = "check-failed", 1, "; ".join(one.check_failures)
                report.check_failures.extend(f"{path}: {failure_line}" for failure_line in one.check_failures)
        except (KeyboardInterrupt, Terminated):
            raise
        except BaseException as exc:  # noqa: BLE001 - one input's failure is its line, the batch goes on
            code, message = failure(exc, None)
            one.status, one.exit_code, one.error = "error", code, message
            report.input_errors.append(f"{path}: {message}")
        one.timings["total"] = round(time.perf_counter() - started, 4)
        one.shaders_compiled = cached_shader_count() - shaders
        report.inputs.append(one.as_dict())
        report.outputs.extend(one.outputs)
        written += [(out, f"an output of input '{path}'") for out in one.outputs]
        report.warnings.extend(f"{path}: {w}" for w in one.warnings)
    return lines
