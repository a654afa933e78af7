# SPDX-License-Identifier: GPL-3.0-or-later
"""The command line's parser: every command and option (the bake settings' options come from
their one definition, options.py)."""
from __future__ import annotations

import argparse
import re
import sys

from .. import __version__
from .errors import CLIError
from .io import ProcessOutput, Progress
from .options import add_setting_options
from ..core.bake.map_kinds import EXTRA_MAPS, MAP_KINDS


# A batch's file names in --out-dir, unless --out gives them ({input}: the input's name without
# extension, cleaned for file names as object names are).
BATCH_NAME = "{input}_ao.png"  # several meshes of an input: _{object} is added


INPUT_FORMATS = (".obj", ".glb", ".gltf", ".blend")


class _Parser(argparse.ArgumentParser):
    def error(self, message):  # one line, exit 2 (argparse prints usage otherwise)
        raise CLIError(message)


def build_parser() -> argparse.ArgumentParser:
    from ..core.hao.view_settings import RenderSize, ViewAOSettings

    parser = _Parser(prog="hao", description="GPU ambient occlusion for Blender scenes and meshes.")
    parser.add_argument("--version", action="version", version=f"hao {__version__}")
    sub = parser.add_subparsers(dest="command", required=True)
    b = sub.add_parser("bake", help="bake per-texel AO of a mesh into an image file")
    add_bake_arguments(b)
    b.add_argument("--manifest", default=None, metavar="FILE",
                   help="a farm task: bake chunk --chunk of this job manifest (written by 'farm'), its inputs "
                        "relative to --input-root (default: the manifest's root), into --out-dir")
    b.add_argument("--chunk", type=int, default=None, help="with --manifest: the chunk to bake (0 is the first)")
    b.add_argument("--input-root", default=None, metavar="DIR", help="with --manifest: the folder of its inputs")
    b.add_argument("--progress", choices=("terminal", "openjd"), default="terminal",
                   help=f"terminal: a progress line on a terminal, or, with stderr redirected to a log, a line every "
                        f"{Progress.LOG_INTERVAL:g} s once a run has lasted {Progress.LOG_INTERVAL:g} s; openjd: "
                        "'openjd_progress: P' lines on stdout "
                        "(Open Job Description's form, for farm tasks)")
    add_run_options(b)

    from .farm_formats import add_farm_parsers
    add_farm_parsers(sub, add_bake_arguments, add_run_options)

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
    add_run_options(r)
    return parser


# --maps: each map's own output option (argparse dest), its file named after --out with _MAP.
MAP_OUTPUTS = {kind.name: kind.option for kind in MAP_KINDS}
# The image options besides --out (each an image bake: not with a colour attribute).
IMAGE_OPTIONS = tuple(kind.option for kind in EXTRA_MAPS)
# Every output option besides --out and --json: the maps' and the glTF file.
EXTRA_OUTPUT_OPTIONS = (*IMAGE_OPTIONS, "gltf_out")


def add_bake_arguments(b: argparse.ArgumentParser) -> None:
    """What a bake takes (bake, and the farm commands that write bake jobs): inputs, outputs,
    frames and every bake setting."""
    from ..core.bake.job_options import JobOptions
    from ..core.bake.settings import BakeSettings

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
                   help="bake every visible mesh of each input (each into its own file); without it and without --object, "
                        "an input with several meshes bakes a .blend's active object (and says so) or is refused")
    add_setting_options(b, BakeSettings)
    b.add_argument("--uv-map", default="auto", help="UV map name, or 'auto' (first UV map, else an automatic unwrap)")
    b.add_argument("--object", action="append", default=None, metavar="NAME",
                   help="mesh to bake (default: the input's only mesh, else a .blend's active object); repeatable: each into its own "
                        "file ({object} in --out, else _NAME is added), or with --texture-set all into one")
    b.add_argument("--high-poly", action="append", default=None, metavar="PATH_OR_NAME",
                   help="Selected to Active: bake this high-poly onto the low-poly's UVs (repeatable): a "
                        ".obj/.glb/.gltf/.blend file whose meshes are the sources, or the name of a mesh in INPUT; "
                        "the low-poly (--object, default the only other mesh or the active one) does not occlude")
    b.add_argument("--cage", default="", metavar="NAME",
                   help="Selected to Active: a mesh in INPUT with the low-poly's topology that the rays start from "
                        "(instead of --cage-extrusion)")
    b.add_argument("--maps", default="", metavar="MAP[,MAP...]",
                   help="the maps to bake, comma-separated, from " + ", ".join(MAP_OUTPUTS) + " (the AO always): "
                        "each map without its own --...-out option is written beside --out, its name followed by "
                        "_MAP (ao.png -> ao_thickness.png); bent normals and the ORM texture come from the AO's "
                        "own pass, thickness from a second one")
    for kind in EXTRA_MAPS:
        b.add_argument(kind.flag, default="", metavar="FILE",
                       help=f"also bake {kind.help}, into this .png (16-bit) or .exr (32-bit float) file"
                            f"{'; ' + kind.note if kind.note else ''}; {{object}} as in --out")
    b.add_argument("--gltf-out", default="", metavar="FILE.glb",
                   help="also write the baked object as a .glb with the map as its material's occlusionTexture "
                        "(Blender's glTF exporter; the map on the UV map that was baked)")
    add_setting_options(b, JobOptions)  # --occluders, --texture-set, --bent-space, --bent-convention


def add_run_options(p: argparse.ArgumentParser) -> None:
    p.add_argument("--json", default=None, metavar="PATH",
                   help="write a machine-readable report to PATH ('-': standard output)")
    p.add_argument("--quiet", action="store_true", help="print nothing unless it fails")


# Options whose value may start with '-' (argparse takes '-5-10' for an option otherwise).
DASH_VALUE_OPTIONS = ("--frames",)


def parse(argv: list[str], io: ProcessOutput) -> argparse.Namespace:
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
