# SPDX-License-Identifier: GPL-3.0-or-later
"""Table-driven bad input: every class gets one clear line and loses nothing.

Command line (``bake``, ``render-ao``, ``farm``): the exit code, stderr exactly one
``hao: error:`` line naming the problem, nothing on stdout, no file in the output folder or
the temporary folder (Blender's own ``blender_*`` included), and every input file unchanged.
The cases run as processes of their own, as many at once as there are cores (cli_runs). Operators: the
report, and the scene unchanged (no image, UV map, attribute or material added).
"""
from __future__ import annotations

import hashlib
import json
import os
import re
import shutil
import subprocess
import sys
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import pytest

import bpy
from conftest import ROOT, select_only, small_settings

SPOT = ROOT / "samples" / "spot.obj"

# Made by a child Blender (this process's bpy session is shared by the other tests).
FIXTURE_SCRIPT = r'''
import os, sys
import bpy
import numpy as np
out = sys.argv[-1]

def fresh():
    bpy.ops.wm.read_factory_settings(use_empty=True)

def save(name):
    bpy.ops.wm.save_as_mainfile(filepath=os.path.join(out, name))

def cube(kind=None, uv=True):
    bpy.ops.mesh.primitive_cube_add(location=(0, 0, 1))
    obj = bpy.context.active_object
    obj.name = "Box"
    if not uv:
        obj.data.uv_layers.remove(obj.data.uv_layers[0])
    co = np.empty(len(obj.data.vertices) * 3, np.float32)
    obj.data.vertices.foreach_get("co", co)
    if kind == "nan":
        co[4] = np.nan
    if kind == "inf":
        co[4] = np.inf
    obj.data.vertices.foreach_set("co", co)
    obj.data.update()
    return obj

def camera():
    bpy.ops.object.camera_add(location=(0, -6, 2), rotation=(1.3, 0, 0))
    bpy.context.scene.camera = bpy.context.active_object

fresh(); cube(); bpy.ops.mesh.primitive_plane_add(size=10); camera(); save("scene.blend")
fresh(); cube(); save("nocamera.blend")
fresh(); camera(); save("nomesh.blend")
fresh(); cube("nan"); save("nan.blend")
fresh(); cube("inf"); save("inf.blend")
fresh(); cube("inf", uv=False); save("inf_nouv.blend")
fresh()
mesh = bpy.data.meshes.new("Points")
mesh.from_pydata([(0, 0, 0), (1, 0, 0), (0, 1, 0)], [], [])
bpy.context.scene.collection.objects.link(bpy.data.objects.new("Points", mesh))
save("nofaces.blend")
fresh(); cube(); camera(); bpy.context.scene.camera.data.clip_end = 0.5; save("farclip.blend")
fresh(); cube(); bpy.context.active_object.name = "a b"; bpy.ops.mesh.primitive_cube_add(location=(3, 0, 0))
bpy.context.active_object.name = "a_b"; save("twins.blend")
fresh(); cube(); bpy.ops.mesh.primitive_cube_add(location=(3, 0, 0)); bare = bpy.context.active_object
bare.name = "Bare"; bare.data.uv_layers.remove(bare.data.uv_layers[0]); save("nouv_pair.blend")
fresh(); bpy.ops.mesh.primitive_plane_add(size=2); bpy.context.active_object.name = "Low"
bpy.ops.mesh.primitive_cube_add(location=(0, 0, 3), size=1); bpy.context.active_object.name = "High"
save("pair.blend")  # the high-poly far above the low-poly: no ray from it finds it
fresh(); cube(); bpy.ops.export_scene.gltf(filepath=os.path.join(out, "scene.glb"))
sys.stdout.flush()
os._exit(0)  # bpy 4.2 segfaults at interpreter exit after a glTF export
'''


@pytest.fixture(scope="module")
def inputs(tmp_path_factory) -> Path:
    folder = tmp_path_factory.mktemp("inputs")
    proc = subprocess.run([sys.executable, "-c", FIXTURE_SCRIPT, str(folder)], capture_output=True, text=True,
                          timeout=300)
    assert proc.returncode == 0, proc.stderr[-2000:]
    (folder / "blend1").mkdir()
    for leftover in folder.glob("*.blend1"):
        leftover.unlink()
    shutil.copy(SPOT, folder / "spot.obj")
    blend, glb = (folder / "scene.blend").read_bytes(), (folder / "scene.glb").read_bytes()
    junk = bytes(range(256)) * 12
    files = {
        "trunc.blend": blend[:200], "garbage.blend": junk, "trunc.glb": glb[:300], "garbage.glb": junk,
        "bad.gltf": b'{"asset": ', "binary.obj": junk, "text.obj": b"this is not a mesh\n", "empty.obj": b"",
        "noface.obj": b"v 0 0 0\nv 1 0 0\nv 0 1 0\n",
        "degenerate.obj": b"v 0 0 0\nv 1 1 1\nv 2 2 2\nf 1 2 3\n",
        "zerouv.obj": b"v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0.5 0.5\nf 1/1 2/1 3/1\n",
        "mesh.fbx": b"Kaydara FBX Binary  \x00", "spot.obj.png": b"not an image",
    }
    for name, data in files.items():
        (folder / name).write_bytes(data)
    (folder / "folder.obj").mkdir()
    (folder / "dir.png").mkdir()
    for sub in ("a", "b"):  # one name in two folders
        (folder / sub).mkdir()
        (folder / sub / "x.obj").write_bytes(files["degenerate.obj"])
    for name in ("a b.obj", "a_b.obj"):  # two names that clean to one
        (folder / name).write_bytes(files["degenerate.obj"])
    (folder / "manifest.json").write_text(json.dumps(  # a farm job's, of one input
        {"version": 1, "root": str(folder), "entries": ["spot.obj"], "chunk_size": 1, "out": "{input}_ao.png",
         "frames": ""}))
    return folder


def digest(folder: Path) -> dict[str, str]:
    return {str(p.relative_to(folder)): hashlib.sha256(p.read_bytes()).hexdigest()
            for p in sorted(folder.rglob("*")) if p.is_file()}


def unwritable_folder(tmp: Path) -> Path:
    """A folder where no file can be created, whoever runs the tests (root ignores modes)."""
    if os.geteuid() == 0:
        return Path("/sys")
    locked = tmp / "locked"
    locked.mkdir()
    locked.chmod(0o500)
    return locked


# (id, arguments ({in}: the inputs folder, {out}: a fresh output folder), exit code, message)
BAKE = "bake"
RENDER = "render-ao"
FARM = "farm"
CASES = [
    # input files
    ("missing-input", [BAKE, "{in}/missing.obj", "--out", "{out}/a.png"], 2, "input file not found"),
    ("input-is-folder", [BAKE, "{in}/folder.obj", "--out", "{out}/a.png"], 2, "is a folder, not a file"),
    ("empty-input", [BAKE, "{in}/empty.obj", "--out", "{out}/a.png"], 2, "is empty"),
    ("unsupported-input", [BAKE, "{in}/mesh.fbx", "--out", "{out}/a.png"], 2, "unsupported input '.fbx'"),
    ("truncated-blend", [BAKE, "{in}/trunc.blend", "--out", "{out}/a.png"], 2, "cannot read 'trunc.blend'"),
    ("garbage-blend", [BAKE, "{in}/garbage.blend", "--out", "{out}/a.png"], 2, "cannot read 'garbage.blend'"),
    ("truncated-glb", [BAKE, "{in}/trunc.glb", "--out", "{out}/a.png"], 2, "cannot read 'trunc.glb'"),
    ("garbage-glb", [BAKE, "{in}/garbage.glb", "--out", "{out}/a.png"], 2, "cannot read 'garbage.glb'"),
    ("truncated-gltf", [BAKE, "{in}/bad.gltf", "--out", "{out}/a.png"], 2, "cannot read 'bad.gltf'"),
    ("binary-obj", [BAKE, "{in}/binary.obj", "--out", "{out}/a.png"], 2, "contains no mesh object"),
    ("text-not-obj", [BAKE, "{in}/text.obj", "--out", "{out}/a.png"], 2, "contains no mesh object"),
    ("obj-without-faces", [BAKE, "{in}/noface.obj", "--out", "{out}/a.png"], 2, "has no faces"),
    ("blend-without-faces", [BAKE, "{in}/nofaces.blend", "--out", "{out}/a.png"], 2, "has no faces"),
    ("blend-without-mesh", [BAKE, "{in}/nomesh.blend", "--out", "{out}/a.png"], 2, "contains no mesh object"),
    ("nan-coordinates", [BAKE, "{in}/nan.blend", "--out", "{out}/a.png"], 2, "NaN or infinite"),
    ("inf-coordinates", [BAKE, "{in}/inf.blend", "--out", "{out}/a.png"], 2, "NaN or infinite"),
    ("inf-coordinates-unwrap", [BAKE, "{in}/inf_nouv.blend", "--out", "{out}/a.png"], 2, "cannot unwrap"),
    ("zero-area-triangles", [BAKE, "{in}/degenerate.obj", "--out", "{out}/a.png"], 2, "only zero-area triangles"),
    ("zero-area-uvs", [BAKE, "{in}/zerouv.obj", "--out", "{out}/a.png"], 2, "every UV triangle has zero area"),
    # numeric options: out of range, not a number, not finite
    ("size-zero", [BAKE, "{in}/spot.obj", "--out", "{out}/a.png", "--size", "0"], 2, "map size must be between 16"),
    ("size-huge", [BAKE, "{in}/spot.obj", "--out", "{out}/a.png", "--size", "20000"], 2, "map size must be"),
    ("size-not-a-number", [BAKE, "{in}/spot.obj", "--out", "{out}/a.png", "--size", "big"], 2, "invalid int value"),
    ("directions-zero", [BAKE, "{in}/spot.obj", "--out", "{out}/a.png", "--directions", "0"], 2, "directions must"),
    ("directions-float", [BAKE, "{in}/spot.obj", "--out", "{out}/a.png", "--directions", "2.5"], 2, "invalid int"),
    ("max-distance-negative", [BAKE, "{in}/spot.obj", "--out", "{out}/a.png", "--max-distance", "-1"], 2,
     "max distance must be at least 0"),
    ("max-distance-nan", [BAKE, "{in}/spot.obj", "--out", "{out}/a.png", "--max-distance", "nan"], 2,
     "max distance must be a finite number"),
    ("max-distance-inf", [BAKE, "{in}/spot.obj", "--out", "{out}/a.png", "--max-distance", "inf"], 2,
     "max distance must be a finite number"),
    ("margin-negative", [BAKE, "{in}/spot.obj", "--out", "{out}/a.png", "--margin", "-1"], 2, "margin must be"),
    ("view-samples-zero", [BAKE, "{in}/spot.obj", "--out", "{out}/a.png", "--view-samples", "0"], 2,
     "view samples must be between 0.25"),
    ("seed-negative", [BAKE, "{in}/spot.obj", "--out", "{out}/a.png", "--seed", "-1"], 2, "(--seed)"),
    ("unknown-falloff", [BAKE, "{in}/spot.obj", "--out", "{out}/a.png", "--falloff", "cubic"], 2, "invalid choice"),
    ("cage-without-high-poly", [BAKE, "{in}/spot.obj", "--out", "{out}/a.png", "--cage", "spot"], 2,
     "--cage needs --high-poly"),
    # names
    ("unknown-uv-map", [BAKE, "{in}/spot.obj", "--out", "{out}/a.png", "--uv-map", "Nope"], 2,
     "no UV map named 'Nope'"),
    ("unknown-object", [BAKE, "{in}/spot.obj", "--out", "{out}/a.png", "--object", "Nope"], 2,
     "no mesh object named 'Nope'"),
    ("unknown-option", [BAKE, "{in}/spot.obj", "--out", "{out}/a.png", "--frobnicate"], 2, "unrecognized arguments"),
    ("unknown-command", ["frobnicate"], 2, "invalid choice"),
    ("no-arguments", [], 2, "required"),
    # outputs
    ("output-extension", [BAKE, "{in}/spot.obj", "--out", "{out}/a.jpg"], 2, "unsupported output extension"),
    ("output-equals-input", [BAKE, "{in}/scene.blend", "--out", "{in}/scene.blend"], 2, "unsupported output extension"),
    ("output-is-input", [RENDER, "{in}/spot.obj.png", "--out", "{in}/spot.obj.png"], 2, "unsupported input"),
    ("output-folder-under-a-file", [BAKE, "{in}/spot.obj", "--out", "{in}/spot.obj/no/a.png"], 2,
     "spot.obj' is a file, not a folder"),
    ("output-folder-is-file", [BAKE, "{in}/spot.obj", "--out", "{in}/spot.obj/a.png"], 2, "is a file, not a folder"),
    ("output-unwritable", [BAKE, "{in}/spot.obj", "--out", "{locked}/a.png"], 2, "permission denied"),
    ("output-name-too-long", [BAKE, "{in}/spot.obj", "--out", "{out}/" + "n" * 260 + ".png"], 2,
     "longer than the file system"),
    ("output-is-folder", [BAKE, "{in}/spot.obj", "--out", "{in}/blend1"], 2, "unsupported output extension"),
    ("output-is-folder-png", [BAKE, "{in}/spot.obj", "--out", "{in}/dir.png"], 2, "it is a folder"),
    ("report-folder-missing", [BAKE, "{in}/spot.obj", "--out", "{out}/a.png", "--json", "{in}/spot.obj/r.json"], 2,
     "cannot write the report"),
    ("texture-set-one-object", [BAKE, "{in}/spot.obj", "--out", "{out}/a.png", "--texture-set"], 2,
     "--texture-set bakes several meshes"),
    ("object-twice", [BAKE, "{in}/spot.obj", "--out", "{out}/a.png", "--object", "spot", "--object", "spot"], 2,
     "names the same mesh twice"),
    ("match-names-with-high-poly", [BAKE, "{in}/spot.obj", "--out", "{out}/a.png", "--match-names", "--high-poly",
                                    "spot"], 2, "--match-names finds the meshes by name: --high-poly does not apply"),
    ("thickness-colour-attribute", [BAKE, "{in}/spot.obj", "--target", "color-attribute", "--out", "{out}/m.ply",
                                    "--thickness-out", "{out}/t.png"], 2, "--thickness-out, --orm-out, --error-out and --gltf-out are image"),
    ("orm-colour-attribute", [BAKE, "{in}/spot.obj", "--target", "color-attribute", "--out", "{out}/m.ply",
                              "--orm-out", "{out}/o.png"], 2, "--orm-out, --error-out and --gltf-out are image bakes"),
    ("error-colour-attribute", [BAKE, "{in}/spot.obj", "--target", "color-attribute", "--out", "{out}/m.ply",
                                "--error-out", "{out}/e.exr"], 2, "--error-out and --gltf-out are image bakes"),
    ("max-error-range", [BAKE, "{in}/spot.obj", "--out", "{out}/a.png", "--max-error", "0.7"], 2,
     "--max-error"),
    ("verify-bound-without-verify", [BAKE, "{in}/spot.obj", "--out", "{out}/a.png", "--verify-max-error", "0.01"], 2,
     "add --verify N"),
    ("maps-unknown", [BAKE, "{in}/spot.obj", "--out", "{out}/a.png", "--maps", "ao,curvature"], 2,
     "--maps: unknown map 'curvature'"),
    ("dither-16-bit", [BAKE, "{in}/spot.obj", "--out", "{out}/a.png", "--dither"], 2, "add --png-bits 8"),
    ("match-names-no-group", [BAKE, "{in}/spot.obj", "--out", "{out}/a.png", "--match-names"], 2,
     "no mesh name (or collection) ends in '_low'"),
    ("match-names-same-suffixes", [BAKE, "{in}/spot.obj", "--out", "{out}/a.png", "--match-names", "--low-suffix",
                                   "_x", "--high-suffix", "_X"], 2, "suffixes must differ"),
    ("frames-backwards", [BAKE, "{in}/spot.obj", "--out", "{out}/a.png", "--frames", "9-1"], 2,
     "the range must run forwards"),
    ("frames-not-a-range", [BAKE, "{in}/spot.obj", "--out", "{out}/a.png", "--frames", "first-last"], 2,
     "expected A-B or A-B:STEP"),
    # the colour-attribute target: --out is the mesh file to save
    ("color-attribute-image-out", [BAKE, "{in}/spot.obj", "--out", "{out}/a.png", "--target", "color-attribute"], 2,
     "--out must be a .blend or .glb or .ply file"),
    ("color-attribute-out-is-input", [BAKE, "{in}/scene.blend", "--out", "{in}/scene.blend", "--target",
                                      "color-attribute"], 2, "is the input file"),
    ("color-attribute-with-gltf-out", [BAKE, "{in}/spot.obj", "--out", "{out}/a.glb", "--target", "color-attribute",
                                       "--gltf-out", "{out}/b.glb"], 2, "are image bakes"),
    ("unknown-color-domain", [BAKE, "{in}/spot.obj", "--out", "{out}/a.glb", "--target", "color-attribute",
                              "--color-domain", "face"], 2, "invalid choice"),
    # render-ao
    ("render-missing-input", [RENDER, "{in}/missing.blend", "--out", "{out}/a.png"], 2, "input file not found"),
    ("render-no-camera", [RENDER, "{in}/nocamera.blend", "--out", "{out}/a.png"], 2, "no camera"),
    ("render-unknown-camera", [RENDER, "{in}/scene.blend", "--out", "{out}/a.png", "--camera", "Nope"], 2,
     "no camera named 'Nope'"),
    ("render-no-mesh", [RENDER, "{in}/nomesh.blend", "--out", "{out}/a.png"], 2, "no visible mesh objects"),
    ("render-width-huge", [RENDER, "{in}/scene.blend", "--out", "{out}/a.png", "--width", "100000"], 2,
     "width must be between 1 and 65536"),
    ("render-beyond-texture-limit", [RENDER, "{in}/scene.blend", "--out", "{out}/a.png", "--width", "65536",
                                     "--height", "8"], 2, "texture limit"),
    ("render-beyond-memory", [RENDER, "{in}/scene.blend", "--out", "{out}/a.png", "--width", "16384",
                              "--height", "16384"], 2, "MiB of GPU memory"),
    ("render-height-zero", [RENDER, "{in}/scene.blend", "--out", "{out}/a.png", "--height", "0"], 2, "height must"),
    ("render-rays-zero", [RENDER, "{in}/scene.blend", "--out", "{out}/a.png", "--rays", "0"], 2, "rays must"),
    ("render-grid-small", [RENDER, "{in}/scene.blend", "--out", "{out}/a.png", "--grid", "32"], 2,
     "grid must be between 64 and 512"),
    ("render-distance-negative", [RENDER, "{in}/scene.blend", "--out", "{out}/a.png", "--max-distance", "-1"], 2,
     "max distance must be at least 0"),
    ("render-scale-zero", [RENDER, "{in}/scene.blend", "--out", "{out}/a.png", "--scale", "0"], 2, "scale must"),
    ("render-filter-negative", [RENDER, "{in}/scene.blend", "--out", "{out}/a.png", "--filter", "-1"], 2,
     "(--filter)"),
    ("render-epsilon-one", [RENDER, "{in}/scene.blend", "--out", "{out}/a.png", "--epsilon", "1"], 2,
     "epsilon must be"),
    ("render-unknown-method", [RENDER, "{in}/scene.blend", "--out", "{out}/a.png", "--method", "ssao"], 2,
     "invalid choice"),
    ("render-spheres-negative", [RENDER, "{in}/scene.blend", "--out", "{out}/a.png", "--spheres", "-1"], 2,
     "--spheres must be"),
    ("render-spheres-no-armature", [RENDER, "{in}/scene.blend", "--out", "{out}/a.png", "--spheres", "8"], 2,
     "no mesh with an Armature modifier"),
    ("render-frame-not-a-number", [RENDER, "{in}/scene.blend", "--out", "{out}/a.png", "--frame", "x"], 2,
     "invalid int value"),
    ("render-output-folder-under-a-file", [RENDER, "{in}/scene.blend", "--out", "{in}/spot.obj/no/a.png"], 2,
     "is a file, not a folder"),
    ("render-output-extension", [RENDER, "{in}/scene.blend", "--out", "{out}/a.tif"], 2,
     "unsupported output extension"),
    ("render-everything-beyond-far-clip", [RENDER, "{in}/farclip.blend", "--out", "{out}/a.png", "--width", "32",
                                           "--height", "24"], 2, "no visible mesh objects in the view of 'Camera'"),
    ("render-report-is-input", [RENDER, "{in}/scene.blend", "--out", "{out}/a.png", "--json", "{in}/scene.blend"], 2,
     "the report (--json) would overwrite the input file"),
    ("render-report-is-output", [RENDER, "{in}/scene.blend", "--out", "{out}/a.png", "--json", "{out}/a.png"], 2,
     "the AO image (--out) and the report (--json) would both be written to"),
    # issue 28: one check of every file a run reads and writes (core/output_files.py)
    ("report-is-input", [BAKE, "{in}/spot.obj", "--out", "{out}/a.png", "--json", "{in}/spot.obj"], 2,
     "the report (--json) would overwrite the input file"),
    ("report-is-output", [BAKE, "{in}/spot.obj", "--out", "{out}/a.png", "--json", "{out}/a.png"], 2,
     "the report (--json) and the AO map (--out) would both be written to"),
    ("report-is-output-other-case", [BAKE, "{in}/spot.obj", "--out", "{out}/a.png", "--json", "{out}/A.PNG"], 2,
     "would both be written to"),
    ("report-is-output-through-dots", [BAKE, "{in}/spot.obj", "--out", "{out}/a.png", "--json", "{out}/../out/a.png"],
     2, "would both be written to"),
    ("report-is-bent-normals", [BAKE, "{in}/spot.obj", "--out", "{out}/a.png", "--bent-normal-out", "{out}/b.png",
                                "--json", "{out}/b.png"], 2, "the bent normals (--bent-normal-out)"),
    ("report-is-gltf", [BAKE, "{in}/spot.obj", "--out", "{out}/a.png", "--gltf-out", "{out}/a.glb", "--json",
                        "{out}/a.glb"], 2, "the report (--json) and the glTF file (--gltf-out) would both be"),
    ("report-is-object-map", [BAKE, "{in}/spot.obj", "--out", "{out}/{object}.png", "--json", "{out}/spot.png"], 2,
     "the AO map of 'spot' and the report (--json) would both be written to"),
    ("report-is-high-poly", [BAKE, "{in}/pair.blend", "--out", "{out}/a.png", "--object", "Low", "--high-poly",
                             "{in}/scene.glb", "--json", "{in}/scene.glb"], 2, "would overwrite the high-poly file"),
    ("report-is-folder", [BAKE, "{in}/spot.obj", "--out", "{out}/a.png", "--json", "{in}/blend1"], 2,
     "cannot write the report"),
    ("report-is-mesh-out", [BAKE, "{in}/spot.obj", "--out", "{out}/a.glb", "--target", "color-attribute", "--json",
                            "{out}/a.glb"], 2, "the mesh file (--out) would both be written to"),
    ("bent-normals-are-the-map", [BAKE, "{in}/spot.obj", "--out", "{out}/a.png", "--bent-normal-out", "{out}/a.png"],
     2, "the AO map (--out) and the bent normals (--bent-normal-out) would both be written to"),
    ("bent-normals-extension", [BAKE, "{in}/spot.obj", "--out", "{out}/a.png", "--bent-normal-out", "{out}/b.jpg"],
     2, "unsupported output extension"),
    ("bent-normals-unknown-space", [BAKE, "{in}/spot.obj", "--out", "{out}/a.png", "--bent-normal-out",
                                    "{out}/b.png", "--bent-space", "world"], 2, "invalid choice"),
    ("gltf-out-is-input", [BAKE, "{in}/scene.glb", "--out", "{out}/a.png", "--gltf-out", "{in}/scene.glb"], 2,
     "is the input file"),
    ("gltf-out-extension", [BAKE, "{in}/spot.obj", "--out", "{out}/a.png", "--gltf-out", "{out}/a.gltf"], 2,
     "--gltf-out must be a .glb"),
    ("color-attribute-with-bent-normals", [BAKE, "{in}/spot.obj", "--out", "{out}/a.glb", "--target",
                                           "color-attribute", "--bent-normal-out", "{out}/b.png"], 2,
     "are image bakes"),
    ("object-names-clean-alike", [BAKE, "{in}/twins.blend", "--all-meshes", "--out", "{out}/{object}.png"], 2,
     "the AO map of 'a b' and the AO map of 'a_b' would both be written to"),
    ("all-meshes-none", [BAKE, "{in}/nomesh.blend", "--all-meshes", "--out", "{out}/a.png"], 2,
     "contains no mesh object"),
    # batches
    ("batch-same-name-two-folders", [BAKE, "{in}/a/x.obj", "{in}/b/x.obj", "--out-dir", "{out}"], 2,
     "the AO map (--out) of input '{in}/a/x.obj' and the AO map (--out) of input '{in}/b/x.obj' would both"),
    ("batch-names-clean-alike", [BAKE, "{in}/a b.obj", "{in}/a_b.obj", "--out-dir", "{out}"], 2,
     "would both be written to '{out}/a_b_ao.png'"),
    ("batch-without-input-token", [BAKE, "{in}/a/x.obj", "{in}/spot.obj", "--out-dir", "{out}", "--out", "m.png"],
     2, "would write every input's map to the same file"),
    ("batch-out-is-a-path", [BAKE, "{in}/spot.obj", "--out-dir", "{out}", "--out", "sub/{input}.png"], 2,
     "is a file name in it, not a path"),
    ("batch-out-dir-under-a-file", [BAKE, "{in}/spot.obj", "--out-dir", "{in}/spot.obj/missing"], 2,
     "is a file, not a folder"),
    ("batch-without-out-dir", [BAKE, "{in}/spot.obj", "{in}/a/x.obj", "--out", "{out}/a.png"], 2,
     "give --out-dir DIR"),
    ("batch-one-gltf-for-all", [BAKE, "{in}/spot.obj", "{in}/a/x.obj", "--out-dir", "{out}", "--gltf-out",
                                "{out}/m.glb"], 2, "would both be written to"),
    ("batch-report-is-an-input", [BAKE, "{in}/spot.obj", "{in}/a/x.obj", "--out-dir", "{out}", "--json",
                                  "{in}/a/x.obj"], 2, "the report (--json) would overwrite input"),
    # frame sequences
    ("frames-a-billion", [BAKE, "{in}/spot.obj", "--out", "{out}/a.png", "--frames", "1-1000000000"], 2,
     "asks for 1000000000 frames, more than 10000"),
    ("frames-step-zero", [BAKE, "{in}/spot.obj", "--out", "{out}/a.png", "--frames", "1-5:0"], 2,
     "a step of at least 1"),
    ("frames-negative-backwards", [BAKE, "{in}/spot.obj", "--out", "{out}/a.png", "--frames", "-1--5"], 2,
     "the range must run forwards"),
    ("frames-names-the-first-frame", [BAKE, "{in}/spot.obj", "--out", "{in}/spot.obj/{frame}.png", "--frames", "5-6"], 2,
     "spot.obj/0005.png': cannot make its folder"),
    ("frames-into-a-color-attribute", [BAKE, "{in}/spot.obj", "--out", "{out}/a.glb", "--target", "color-attribute",
                                       "--frames", "1-2"], 2, "a colour attribute holds one frame"),
    # Selected to Active
    ("high-poly-all-rays-miss", [BAKE, "{in}/pair.blend", "--out", "{out}/a.png", "--object", "Low", "--high-poly",
                                 "High", "--size", "32", "--directions", "4"], 2, "found a high-poly surface"),
    ("cage-extrusion-beyond-float32", [BAKE, "{in}/pair.blend", "--out", "{out}/a.png", "--object", "Low",
                                       "--high-poly", "High", "--cage-extrusion", "1e9", "--size", "32"], 2,
     "a cage extrusion of 1e+09 is too far for 'Low'"),
    ("cage-extrusion-negative", [BAKE, "{in}/pair.blend", "--out", "{out}/a.png", "--object", "Low", "--high-poly",
                                 "High", "--cage-extrusion", "-1"], 2, "(--cage-extrusion)"),
    ("max-ray-distance-negative", [BAKE, "{in}/pair.blend", "--out", "{out}/a.png", "--object", "Low",
                                   "--high-poly", "High", "--max-ray-distance", "-1"], 2, "(--max-ray-distance)"),
    ("high-poly-is-the-low-poly", [BAKE, "{in}/pair.blend", "--out", "{out}/a.png", "--object", "Low",
                                   "--high-poly", "Low"], 2, "cannot be both the high-poly and the low-poly"),
    ("high-poly-unknown", [BAKE, "{in}/pair.blend", "--out", "{out}/a.png", "--high-poly", "Nope"], 2,
     "--high-poly 'Nope' is neither a mesh file nor a mesh"),
    ("high-poly-file-missing", [BAKE, "{in}/pair.blend", "--out", "{out}/a.png", "--high-poly", "{in}/none.obj"],
     2, "--high-poly: input file not found"),
    ("high-poly-onto-two-objects", [BAKE, "{in}/twins.blend", "--out", "{out}/{object}.png", "--object", "a b",
                                    "--object", "a_b", "--high-poly", "{in}/pair.blend"], 2,
     "bakes onto one low-poly"),
    ("cage-unknown", [BAKE, "{in}/pair.blend", "--out", "{out}/a.png", "--object", "Low", "--high-poly", "High",
                      "--cage", "Nope"], 2, "--cage: no mesh object named 'Nope'"),
    # texture sets and anti-aliasing
    ("texture-set-object-without-uvs", [BAKE, "{in}/nouv_pair.blend", "--out", "{out}/a.png", "--texture-set",
                                        "--object", "Box", "--object", "Bare"], 2,
     "'Bare' has no UV map: a texture set bakes each object's own UVs"),
    ("samples-per-texel-unknown", [BAKE, "{in}/spot.obj", "--out", "{out}/a.png", "--samples-per-texel", "3"], 2,
     "invalid choice"),
    ("bake-without-input", [BAKE, "--out", "{out}/a.png"], 2, "bake needs an INPUT file (or --manifest FILE)"),
    # farm jobs (issue 29)
    ("farm-without-inputs", [FARM, "openjd", "--out-dir", "{out}", "--bundle", "{out}/job"], 2,
     "farm openjd needs the INPUT files of the job"),
    ("farm-without-out-dir", [FARM, "flamenco", "{in}/spot.obj", "--bundle", "{out}/job"], 2,
     "farm flamenco needs --out-dir DIR"),
    ("farm-without-bundle", [FARM, "opencue", "{in}/spot.obj", "--out-dir", "{out}"], 2,
     "the following arguments are required: --bundle"),
    ("farm-missing-input", [FARM, "openjd", "{in}/none.obj", "--out-dir", "{out}", "--bundle", "{out}/job"], 2,
     "input file not found"),
    ("farm-chunk-size-zero", [FARM, "openjd", "{in}/spot.obj", "--out-dir", "{out}", "--bundle", "{out}/job",
                              "--chunk-size", "0"], 2, "--chunk-size must be at least 1"),
    ("farm-frames-of-two-inputs", [FARM, "openjd", "{in}/spot.obj", "{in}/scene.glb", "--out-dir", "{out}",
                                   "--bundle", "{out}/job", "--frames", "1-9"], 2, "give one input"),
    ("farm-frames-a-billion", [FARM, "openjd", "{in}/spot.obj", "--out-dir", "{out}", "--bundle", "{out}/job",
                               "--frames", "1-1000000000"], 2, "more than 10000"),
    ("farm-unknown-runner", [FARM, "openjd", "{in}/spot.obj", "--out-dir", "{out}", "--bundle", "{out}/job",
                             "--runner", "maya"], 2, "invalid choice"),
    ("farm-out-is-a-path", [FARM, "openjd", "{in}/spot.obj", "--out-dir", "{out}", "--bundle", "{out}/job",
                            "--out", "sub/{input}.png"], 2, "is a file name in it, not a path"),
    ("farm-unknown-format", [FARM, "slurm", "{in}/spot.obj"], 2, "invalid choice"),
    ("task-manifest-and-inputs", [BAKE, "{in}/spot.obj", "--manifest", "{in}/manifest.json", "--out-dir", "{out}"],
     2, "--manifest names the inputs: give no INPUT besides it"),
    ("task-chunk-beyond-the-job", [BAKE, "--manifest", "{in}/manifest.json", "--chunk", "5", "--out-dir", "{out}"],
     2, "chunk 5 is not in this job: it has chunks 0 to 0"),
    ("task-manifest-not-a-manifest", [BAKE, "--manifest", "{in}/spot.obj", "--out-dir", "{out}"], 2,
     "cannot read the manifest"),
    ("task-manifest-without-out-dir", [BAKE, "--manifest", "{in}/manifest.json"], 2,
     "--manifest needs --out-dir DIR"),
    ("verify-outputs-missing", [FARM, "verify", "--manifest", "{in}/manifest.json", "--out-dir", "{out}"], 1,
     "1 of 1 expected outputs are missing, empty or broken: spot_ao.png"),
]


def run_cli(args: list[str], tmp: Path, **kw) -> subprocess.CompletedProcess:
    env = {**os.environ, "PYTHONPATH": str(ROOT), "TMPDIR": str(tmp), "TEMP": str(tmp), "TMP": str(tmp)}
    env.update(kw.pop("env", {}))
    return subprocess.run([sys.executable, "-m", "hao_addon", *args], capture_output=True, text=True, env=env,
                          cwd=kw.pop("cwd", tmp), timeout=300, **kw)


def _case_args(case, inputs: Path, folder: Path) -> tuple[list[str], str, Path, Path]:
    """(arguments, message) of a case with its tokens filled, and its output and temporary
    folders (made here, empty)."""
    _name, template, _code, message = case
    out, tmp = folder / "out", folder / "tmp"
    out.mkdir()
    tmp.mkdir()
    subs = {"{in}": str(inputs), "{out}": str(out), "{locked}": str(unwritable_folder(folder))}
    filled = []
    for arg in template + [message]:
        for token, value in subs.items():
            arg = arg.replace(token, value)
        filled.append(arg)
    return filled[:-1], filled[-1], out, tmp


@pytest.fixture(scope="module")
def cli_runs(inputs, tmp_path_factory) -> tuple[dict, dict]:
    """Every case run once, as many at a time as there are cores (each is a process of its
    own, mostly Python's and Blender's start on one core), each in its own folders; and the
    inputs' digest before them all (each case checks it after them all)."""
    before = digest(inputs)
    prepared = {case[0]: _case_args(case, inputs, tmp_path_factory.mktemp(case[0])) for case in CASES}

    def run(name: str):
        args, _message, _out, tmp = prepared[name]
        return name, run_cli(args, tmp)
    with ThreadPoolExecutor(max_workers=os.cpu_count() or 2) as pool:
        done = dict(pool.map(run, prepared))
    return {name: (done[name], *prepared[name][1:]) for name in prepared}, before


@pytest.mark.parametrize("case", CASES, ids=[c[0] for c in CASES])
def test_cli_bad_input(inputs, cli_runs, case):
    name, _template, code, _message = case
    results, before = cli_runs
    proc, message, out, tmp = results[name]
    assert proc.returncode == code, (proc.returncode, proc.stderr)
    lines = proc.stderr.splitlines()
    assert len(lines) == 1 and lines[0].startswith("hao: error: ") and message in lines[0], proc.stderr
    assert proc.stdout == ""
    assert list(out.iterdir()) == [] and list(tmp.iterdir()) == [], (list(out.iterdir()), list(tmp.iterdir()))
    assert digest(inputs) == before  # no case changed an input (all of them have run)


def test_enough_classes():
    """Issue 28: at least 100 classes across both entry points (the command line's here, the
    operators' below), a class being a refusal the user is told apart: cases that expect the
    same message count once (renaming a copy of a case adds nothing), argparse's own
    messages ('invalid choice', 'unrecognized arguments', ...) once each."""
    told = {("cli", c[3]) for c in CASES}
    told |= {("operator", c[-1]) for c in BAKE_OPERATOR_CASES + RENDER_OPERATOR_CASES}
    assert len({c[0] for c in CASES}) == len(CASES)
    assert len(told) >= 100, len(told)


# -- operators ------------------------------------------------------------------------------------

def scene_state():
    """What a failed operator must not change."""
    meshes = {m.name: (tuple(l.name for l in m.uv_layers), tuple(a.name for a in m.attributes),
                       tuple(mat.name if mat else "" for mat in m.materials)) for m in bpy.data.meshes}
    return (sorted(bpy.data.images.keys()), sorted(bpy.data.materials.keys()), meshes)


def two_cubes(*names):
    objs = []
    for i, name in enumerate(names):
        bpy.ops.mesh.primitive_cube_add(location=(3 * i, 0, 0))
        objs.append(bpy.context.active_object)
        objs[-1].name = name
    select_only(*objs)
    return objs


def _unsaved_relative_path(scene, tmp, a, b):
    assert bpy.data.filepath == ""
    small_settings(scene, filepath="//ao.png")


def _nan_vertex(scene, tmp, a, b):
    b.data.vertices[0].co = (float("nan"), 0.0, 0.0)
    small_settings(scene)


def _no_uv(obj):
    obj.data.uv_layers.remove(obj.data.uv_layers[0])


def _selected_to_active(scene, a, b, **kw):
    bpy.context.view_layer.objects.active = a
    small_settings(scene, selected_to_active=True, **kw)


# (id, setup(scene, tmp_path, a, b) on two selected cubes 'a b' and 'a_b' 3 apart, message)
BAKE_OPERATOR_CASES = [
    ("colliding-names", lambda sc, tmp, a, b: small_settings(sc, filepath=str(tmp / "pair.png")),
     "the AO map of 'a b' and the AO map of 'a_b' would both be written to"),
    ("relative-path-unsaved", _unsaved_relative_path, "relative to the .blend file"),
    ("unsupported-extension", lambda sc, tmp, a, b: small_settings(sc, filepath=str(tmp / "ao.bmp")),
     "unsupported output extension"),
    ("missing-uv-map", lambda sc, tmp, a, b: small_settings(sc, uv_mode='NAMED', uv_map="Nope"),
     "no UV map named 'Nope'"),
    ("nan-vertex", _nan_vertex, "NaN"),
    ("name-too-long", lambda sc, tmp, a, b: small_settings(sc, filepath=str(tmp / ("x" * 300 + ".png"))),
     "longer than the file system"),
    ("nothing-selected", lambda sc, tmp, a, b: select_only(), "Select one or more mesh objects"),
    # issue 28
    ("bent-normals-are-the-map", lambda sc, tmp, a, b: small_settings(
        sc, filepath=str(tmp / "{object}.png"), bent_normals=True, bent_filepath=str(tmp / "{object}.png")),
     "the AO map of 'a b' and the bent normals of 'a b' would both be written to"),
    ("frames-into-a-color-attribute", lambda sc, tmp, a, b: small_settings(sc, target="color-attribute",
                                                                           frame_range=True),
     "a colour attribute holds one frame"),
    ("frames-name-the-first-frame", lambda sc, tmp, a, b: (setattr(sc, "frame_start", 5), small_settings(
        sc, frame_range=True, filepath=str(tmp / "no" / "{frame}.png"))), "/no/0005_"),
    ("texture-set-object-without-uvs", lambda sc, tmp, a, b: (_no_uv(b), small_settings(sc, texture_set=True)),
     "'a_b' has no UV map: a texture set bakes each object's own UVs"),
    ("cage-is-the-only-high-poly", lambda sc, tmp, a, b: _selected_to_active(sc, a, b, cage_object=b),
     "'a_b' cannot be both the high-poly and the low-poly or cage"),
    ("high-poly-all-rays-miss", lambda sc, tmp, a, b: (setattr(b, "location", (3, 3, 3)),  # off every axis ray
                                                       _selected_to_active(sc, a, b)),
     "texels of 'a b' found a high-poly surface"),
    ("cage-extrusion-beyond-float32", lambda sc, tmp, a, b: _selected_to_active(sc, a, b, cage_extrusion=1e9),
     "a cage extrusion of 1e+09 is too far for 'a b'"),
]


@pytest.mark.parametrize("case", BAKE_OPERATOR_CASES, ids=[c[0] for c in BAKE_OPERATOR_CASES])
def test_bake_operator_bad_input(scene, tmp_path, case):
    _name, setup, message = case
    a, b = two_cubes("a b", "a_b")
    frame_start = scene.frame_start
    setup(scene, tmp_path, a, b)
    before = scene_state()
    try:
        with pytest.raises(RuntimeError, match=re.escape(message)):
            bpy.ops.object.hao_bake_ao()
    finally:
        scene.frame_start = frame_start
    assert scene_state() == before
    assert list(tmp_path.iterdir()) == []


RENDER_OPERATOR_CASES = [
    ("resolution-beyond-limits", "texture limit"),
    ("relative-path-unsaved", "relative to the .blend file"),
    ("folder-under-a-file", "is a file, not a folder"),
    ("no-mesh", "no visible mesh objects"),
]


@pytest.mark.parametrize("setup, message", RENDER_OPERATOR_CASES)
def test_render_operator_bad_input(scene, tmp_path, setup, message):
    bpy.ops.object.camera_add(location=(0, -6, 2), rotation=(1.3, 0, 0))
    scene.camera = bpy.context.active_object
    r = scene.render
    saved = (r.resolution_x, r.resolution_y, r.resolution_percentage)
    r.resolution_x, r.resolution_y, r.resolution_percentage = 64, 48, 100
    path = ""
    if setup != "no-mesh":
        bpy.ops.mesh.primitive_cube_add()
    if setup == "resolution-beyond-limits":
        r.resolution_x = 65536
    elif setup == "relative-path-unsaved":
        path = "//hao.png"
    elif setup == "folder-under-a-file":
        (tmp_path / "file").write_bytes(b"")
        path = str(tmp_path / "file" / "no" / "hao.png")
    before, files_before = scene_state(), sorted(tmp_path.rglob("*"))
    try:
        with pytest.raises(RuntimeError, match=message):
            bpy.ops.render.hao_render_ao(filepath=path)
    finally:
        r.resolution_x, r.resolution_y, r.resolution_percentage = saved
    assert scene_state() == before
    assert sorted(tmp_path.rglob("*")) == files_before
