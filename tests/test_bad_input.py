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
from conftest import ROOT, cli_env, run_hao, select_only, small_settings

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
def alpha_card(name, kind):
    """A floor under a card whose alpha comes from the image mask.png beside the file
    ('texture'), from a file that is gone ('missing'), or is NaN ('nan')."""
    fresh()
    bpy.ops.mesh.primitive_plane_add(size=4); bpy.context.active_object.name = "Floor"
    bpy.ops.mesh.primitive_plane_add(size=4, location=(0, 0, 0.5)); card = bpy.context.active_object
    card.name = "Card"
    material = bpy.data.materials.new("CardMaterial")
    material.use_nodes = True
    bsdf = material.node_tree.nodes["Principled BSDF"]
    if kind == "nan":
        bsdf.inputs["Alpha"].default_value = float("nan")
    else:
        image = bpy.data.images.new("mask", 8, 8, alpha=True)
        image.pixels.foreach_set(np.tile([1.0, 1.0, 1.0, 0.5], 64).astype(np.float32))
        path = os.path.join(out, "mask.png" if kind == "texture" else "gone.png")
        image.filepath_raw, image.file_format = path, 'PNG'
        image.save()
        texture = material.node_tree.nodes.new('ShaderNodeTexImage')
        texture.image = image
        material.node_tree.links.new(texture.outputs['Alpha'], bsdf.inputs['Alpha'])
    card.data.materials.append(material)
    save(name)
    if kind == "missing":
        os.remove(os.path.join(out, "gone.png"))

alpha_card("alpha_texture.blend", "texture"); alpha_card("alpha_missing.blend", "missing")
alpha_card("alpha_nan.blend", "nan")
fresh(); cube(); bpy.ops.export_scene.gltf(filepath=os.path.join(out, "scene.glb"))
sys.stdout.flush()
os._exit(0)  # bpy 4.2 segfaults at interpreter exit after a glTF export
'''


def _with(**changes):
    return lambda data: {**data, **changes}


def _without(name):
    return lambda data: {k: v for k, v in data.items() if k != name}


# Manifests a farm task may be handed, each wrong in one way (issue 38): each is refused with
# one line naming the fault, nothing written.
MANIFEST_FAULTS = {
    "list": "[1, 2]", "null": "null", "empty-file": "", "not-json": "{'version': 2}",
    "version-1": _with(version=1), "no-root": _without("root"), "no-outputs": _without("outputs"),
    "chunk-zero": _with(chunk_size=0), "chunk-huge": lambda data: json.dumps(data).replace('"chunk_size": 1', '"chunk_size": 1e400'),
    "chunk-bool": _with(chunk_size=True), "chunk-text": _with(chunk_size="10"),
    "entries-text": _with(entries="spot.obj"), "entries-null": _with(entries=[None]),
    "entries-empty": _with(entries=[]), "entry-absolute": _with(entries=["/etc/passwd"]),
    "entry-up": _with(entries=["../spot.obj"]), "entries-twice": _with(entries=["spot.obj", "spot.obj"]),
    "out-nul": _with(out="a\u0000b.png"), "out-path": _with(out="sub/{input}.png"),
    "root-relative": _with(root="inputs"), "unknown-field": _with(extra=1),
    "frames-bad": _with(frames="1-x"), "outputs-text": _with(outputs="a.png"),
    "entry-newline": _with(entries=["a\nb.obj"]),
}
# A PNG cut short: its header and key survive, its pixels do not.
CUT_PNG = (b"\x89PNG\r\n\x1a\n\x00\x00\x00\rIHDR\x00\x00\x00\x10\x00\x00\x00\x10\x10\x00\x00\x00\x00"
           b"\x8f\x87\xb0\xa6\x00\x00\x01\x00IDAT")
# A folder name that shells and farm parsers treat specially (accepted: it is data).
HOSTILE_FOLDER = "-h $(touch PWNED) `touch PWNED` ; & 'q' \"d\" ünï {{x}} {chunk}"


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
        "uv_outside.obj": b"v 0 0 0\nv 1 0 0\nv 0 1 0\nvt -0.9 -0.9\nvt -0.1 -0.9\nvt -0.9 -0.1\nf 1/1 2/2 3/3\n",
        "uv_tiny.obj": b"v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0.5 0.5\nvt 0.50001 0.5\nvt 0.5 0.50001\nf 1/1 2/2 3/3\n",
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
    good = {"version": 2, "root": str(folder), "entries": ["spot.obj"], "chunk_size": 1, "out": "{input}_ao.png",
            "frames": "", "outputs": ["{input}_ao.png"]}
    (folder / "manifest.json").write_text(json.dumps(good))  # a farm job's, of one input
    for name, fault in MANIFEST_FAULTS.items():
        text = fault if isinstance(fault, str) else fault(dict(good))
        (folder / f"m_{name}.json").write_text(text if isinstance(text, str) else json.dumps(text))
    for name, out in (("cut", "{input}_cut.png"), ("dir", "{input}_dir.png")):  # outputs Verify must refuse
        (folder / f"verify_{name}.json").write_text(json.dumps({**good, "out": out, "outputs": [out]}))
    (folder / "spot_cut.png").write_bytes(CUT_PNG)
    (folder / "spot_dir.png").mkdir()
    hostile = folder / HOSTILE_FOLDER
    hostile.mkdir()
    shutil.copy(SPOT, hostile / "h.obj")
    (folder / "new\nline").mkdir()  # a folder name a cuecmd line would split at
    shutil.copy(SPOT, folder / "new\nline" / "x.obj")
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
                                    "--thickness-out", "{out}/t.png"], 2, "--thickness-out, --orm-out, --error-out, --curvature-out, --cavity-out "
                                                                       "and --gltf-out are image"),
    ("orm-colour-attribute", [BAKE, "{in}/spot.obj", "--target", "color-attribute", "--out", "{out}/m.ply",
                              "--orm-out", "{out}/o.png"], 2, "--orm-out, --error-out, --curvature-out, --cavity-out and --gltf-out are "
                                                        "image bakes"),
    ("error-colour-attribute", [BAKE, "{in}/spot.obj", "--target", "color-attribute", "--out", "{out}/m.ply",
                                "--error-out", "{out}/e.exr"], 2, "--error-out, --curvature-out, --cavity-out and --gltf-out are image bakes"),
    ("max-error-range", [BAKE, "{in}/spot.obj", "--out", "{out}/a.png", "--max-error", "0.7"], 2,
     "--max-error"),
    ("verify-bound-without-verify", [BAKE, "{in}/spot.obj", "--out", "{out}/a.png", "--verify-max-error", "0.01"], 2,
     "add --verify N"),
    ("maps-unknown", [BAKE, "{in}/spot.obj", "--out", "{out}/a.png", "--maps", "ao,roughness"], 2,
     "--maps: unknown map 'roughness'"),
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
    ("task-manifest-not-a-manifest", [BAKE, "--manifest", "{in}/spot.obj", "--chunk", "0", "--out-dir", "{out}"], 2,
     "cannot read the manifest"),
    ("task-manifest-without-out-dir", [BAKE, "--manifest", "{in}/manifest.json"], 2,
     "--manifest needs --out-dir DIR"),
    ("verify-outputs-missing", [FARM, "verify", "--manifest", "{in}/manifest.json", "--out-dir", "{out}"], 1,
     "1 of 1 expected outputs are missing, empty or broken: spot_ao.png"),
    # issue 38: nothing lost, nothing wrong called success
    ("verify-output-cut-short", [FARM, "verify", "--manifest", "{in}/verify_cut.json", "--out-dir", "{in}"], 1,
     "1 of 1 expected outputs are missing, empty or broken: spot_cut.png"),
    ("verify-folder-in-a-maps-place", [FARM, "verify", "--manifest", "{in}/verify_dir.json", "--out-dir", "{in}"],
     1, "1 of 1 expected outputs are missing, empty or broken: spot_dir.png"),
    ("farm-same-name-two-folders", [FARM, "openjd", "{in}/a/x.obj", "{in}/b/x.obj", "--out-dir", "{out}",
                                    "--bundle", "{out}/job"], 2,
     "the AO map (--out) of input '{in}/a/x.obj' and the AO map (--out) of input '{in}/b/x.obj' would both be "
     "written to '{out}/x_ao.png'"),
    ("farm-names-clean-alike", [FARM, "flamenco", "{in}/a b.obj", "{in}/a_b.obj", "--out-dir", "{out}",
                                "--bundle", "{out}/job"], 2, "of input '{in}/a_b.obj' would both be written to "
                                                             "'{out}/a_b_ao.png'"),
    ("farm-without-input-token", [FARM, "opencue", "{in}/a/x.obj", "{in}/spot.obj", "--out-dir", "{out}",
                                  "--bundle", "{out}/job", "--out", "m.png"], 2,
     "--out 'm.png' would write every input's map to the same file: put {input} in it"),
    ("farm-bent-normals-on-the-map", [FARM, "openjd", "{in}/spot.obj", "--out-dir", "{out}", "--bundle",
                                      "{out}/job", "--bent-normal-out", "{input}_ao.png"], 2,
     "the bent normals (--bent-normal-out) of input '{in}/spot.obj' would both be written to '{out}/spot_ao.png'"),
    ("farm-extra-output-absolute", [FARM, "openjd", "{in}/spot.obj", "--out-dir", "{out}", "--bundle", "{out}/job",
                                    "--thickness-out", "/tmp/t.png"], 2,
     "in a farm job, --thickness-out is a file name in --out-dir (the tasks write every output there)"),
    ("farm-extra-output-above", [FARM, "flamenco", "{in}/spot.obj", "--out-dir", "{out}", "--bundle", "{out}/job",
                                 "--gltf-out", "../m.glb"], 2, "in a farm job, --gltf-out is a file name in --out-dir"),
    ("farm-newline-in-an-input-folder", [FARM, "opencue", "{in}/new\nline/x.obj", "--out-dir", "{out}", "--bundle",
                                         "{out}/job"], 2, "an input path contains a control character (a newline)"),
    ("farm-newline-in-the-name", [FARM, "opencue", "{in}/spot.obj", "--out-dir", "{out}", "--bundle", "{out}/job",
                                  "--name", "a\nrm -rf b"], 2,
     "--name contains a control character (a newline): \"a\\nrm -rf b\"; a farm's command line cannot carry it"),
    ("farm-tab-in-the-out-dir", [FARM, "flamenco", "{in}/spot.obj", "--out-dir", "{out}/o\tp", "--bundle",
                                 "{out}/job"], 2, "--out-dir contains a control character (a tab)"),
    ("farm-control-in-the-executable", [FARM, "opencue", "{in}/spot.obj", "--out-dir", "{out}", "--bundle",
                                        "{out}/job", "--executable", "bl\x01ender"], 2,
     "--executable contains a control character (U+0001)"),
    ("farm-carriage-return-in-an-option", [FARM, "openjd", "{in}/spot.obj", "--out-dir", "{out}", "--bundle",
                                           "{out}/job", "--uv-map", "UV\rMap"], 2,
     "a bake option contains a control character (a carriage return)"),
    ("farm-openjd-braces-in-the-name", [FARM, "openjd", "{in}/spot.obj", "--out-dir", "{out}", "--bundle",
                                        "{out}/job", "--name", "job {{Param.OutputDir}}"], 2,
     "--name holds '{{' or '}}', which Open Job Description reads as its own format string"),
    ("farm-openjd-braces-in-an-option", [FARM, "openjd", "{in}/spot.obj", "--out-dir", "{out}", "--bundle",
                                         "{out}/job", "--bent-normal-out", "b}}.png"], 2,
     "a bake option holds '{{' or '}}'"),
    ("farm-chunk-size-huge", [FARM, "openjd", "{in}/spot.obj", "--out-dir", "{out}", "--bundle", "{out}/job",
                              "--chunk-size", "2000000"], 2, "--chunk-size must be at least 1 and at most 1000000"),
    ("farm-frames-past-blender", [FARM, "openjd", "{in}/spot.obj", "--out-dir", "{out}", "--bundle", "{out}/job",
                                  "--frames", "2000000"], 2, "Blender's frames run from -1048574 to 1048574"),
    ("farm-gltf-of-frames", [FARM, "openjd", "{in}/spot.obj", "--out-dir", "{out}", "--bundle", "{out}/job",
                             "--gltf-out", "{input}.glb", "--frames", "1-3"], 2,
     "--gltf-out writes one mesh with one set of maps, --frames a map per frame"),
    ("farm-setting-out-of-range", [FARM, "flamenco", "{in}/spot.obj", "--out-dir", "{out}", "--bundle", "{out}/job",
                                   "--size", "8"], 2, "map size must be between 16 and 16384 texels, got 8 (--size)"),
    ("task-manifest-without-chunk", [BAKE, "--manifest", "{in}/manifest.json", "--out-dir", "{out}"], 2,
     "--manifest needs --chunk N: the task's chunk of the job"),
    ("task-chunk-without-manifest", [BAKE, "{in}/spot.obj", "--out", "{out}/a.png", "--chunk", "3"], 2,
     "--chunk and --input-root belong to a farm task's --manifest"),
    ("task-out-beside-manifest", [BAKE, "--manifest", "{in}/manifest.json", "--chunk", "0", "--out-dir", "{out}",
                                  "--out", "x.png"], 2, "--manifest names the output files: give no --out besides it"),
    ("task-frames-beside-manifest", [BAKE, "--manifest", "{in}/manifest.json", "--chunk", "0", "--out-dir", "{out}",
                                     "--frames", "1-2"], 2, "--manifest names the frames of each chunk"),
    ("scene-texture-as-the-map", [BAKE, "{in}/alpha_texture.blend", "--object", "Floor", "--out", "{in}/mask.png",
                                  "--size", "16"], 2,
     "the AO map of 'Floor' would overwrite the image 'mask' that the scene's materials read"),
    ("scene-texture-as-the-orm", [BAKE, "{in}/alpha_texture.blend", "--object", "Floor", "--out", "{out}/a.png",
                                  "--orm-out", "{in}/mask.png", "--size", "16"], 2,
     "the ORM texture of 'Floor' would overwrite the image 'mask'"),
    ("alpha-image-missing", [BAKE, "{in}/alpha_missing.blend", "--object", "Floor", "--out", "{out}/a.png",
                             "--size", "16"], 2, "that gives material 'CardMaterial' its alpha cannot be read"),
    ("alpha-nan", [BAKE, "{in}/alpha_nan.blend", "--object", "Floor", "--out", "{out}/a.png", "--size", "16"], 2,
     "material 'CardMaterial' has an Alpha of nan"),
    ("uvs-outside-the-tile", [BAKE, "{in}/uv_outside.obj", "--out", "{out}/a.png", "--size", "16"], 2,
     "'uv_outside': no texel centre of the 16x16 map lies inside its UV triangles"),
    ("uvs-smaller-than-a-texel", [BAKE, "{in}/uv_tiny.obj", "--out", "{out}/a.png", "--size", "16",
                                  "--directions", "8"], 2, "'uv_tiny': no texel centre of the 16x16 map lies inside"),
    ("spread-angle-without-a-direction", [BAKE, "{in}/spot.obj", "--out", "{out}/a.png", "--spread-angle", "1e-9"],
     2, "the map would be white; raise the spread angle or Directions"),
    ("spread-angle-zero", [BAKE, "{in}/spot.obj", "--out", "{out}/a.png", "--spread-angle", "0"], 2,
     "spread angle must be above 0 and at most 90 degrees"),
    ("frames-past-blender", [BAKE, "{in}/spot.obj", "--out", "{out}/a.png", "--frames", "1048575"], 2,
     "--frames '1048575': Blender's frames run from"),
    ("frames-before-blender", [BAKE, "{in}/spot.obj", "--out", "{out}/a.png", "--frames", "-2000000--1999999"], 2,
     "--frames '-2000000--1999999': Blender's frames run from"),
    ("low-suffix-empty", [BAKE, "{in}/spot.obj", "--out", "{out}/a.png", "--match-names", "--low-suffix", ""], 2,
     "got '' and '_high' (--low-suffix)"),
    ("png-bits-for-exr", [BAKE, "{in}/spot.obj", "--out", "{out}/a.exr", "--png-bits", "8"], 2,
     "--png-bits 8 is for PNG files, and every output here is a 32-bit float EXR"),
    ("gltf-of-frames", [BAKE, "{in}/spot.obj", "--out", "{out}/a.png", "--gltf-out", "{out}/a.glb", "--frames", "1-2"],
     2, "bake the glTF file of one frame without --frames"),
    ("alpha-clip-above-one", [BAKE, "{in}/spot.obj", "--out", "{out}/a.png", "--alpha-clip", "2"], 2,
     "alpha clip must be between 0 and 1, got 2.0 (--alpha-clip)"),
    ("min-distance-negative", [BAKE, "{in}/spot.obj", "--out", "{out}/a.png", "--min-distance", "-1"], 2,
     "min distance must be at least 0 scene units"),
    ("thickness-distance-negative", [BAKE, "{in}/spot.obj", "--out", "{out}/a.png", "--thickness-out",
                                     "{out}/t.png", "--thickness-distance", "-1"], 2,
     "thickness distance must be at least 0 scene units"),
    ("terminator-offset-above-one", [BAKE, "{in}/spot.obj", "--out", "{out}/a.png", "--terminator-offset", "2"], 2,
     "terminator offset must be between 0 and 1"),
    ("verify-negative", [BAKE, "{in}/spot.obj", "--out", "{out}/a.png", "--verify", "-1"], 2,
     "verified texels must be between 0 and 100000"),
    ("verify-bound-above-half", [BAKE, "{in}/spot.obj", "--out", "{out}/a.png", "--verify", "5",
                                 "--verify-max-error", "2"], 2, "verify max error must be between 0 and 0.5"),
    ("cage-extrusion-nan", [BAKE, "{in}/pair.blend", "--out", "{out}/a.png", "--object", "Low", "--high-poly",
                            "High", "--cage-extrusion", "nan"], 2, "cage extrusion must be a finite number"),
    ("view-samples-above-64", [BAKE, "{in}/spot.obj", "--out", "{out}/a.png", "--view-samples", "100"], 2,
     "view samples must be between 0.25 and 64, got 100.0"),
    ("directions-beyond-the-limit", [BAKE, "{in}/spot.obj", "--out", "{out}/a.png", "--directions", "100000000"],
     2, "directions must be between 1 and 65536"),
    ("thickness-is-the-map", [BAKE, "{in}/spot.obj", "--out", "{out}/a.png", "--thickness-out", "{out}/a.png"], 2,
     "the AO map (--out) and the thickness map (--thickness-out) would both be written to"),
    ("orm-is-the-bent-normals", [BAKE, "{in}/spot.obj", "--out", "{out}/a.png", "--orm-out", "{out}/b.png",
                                 "--bent-normal-out", "{out}/b.png"], 2,
     "the bent normals (--bent-normal-out) and the ORM texture (--orm-out) would both be written to"),
    ("error-is-the-thickness", [BAKE, "{in}/spot.obj", "--out", "{out}/a.png", "--error-out", "{out}/t.png",
                                "--thickness-out", "{out}/t.png"], 2,
     "the thickness map (--thickness-out) and the error map (--error-out) would both be written to"),
    ("maps-thickness-onto-the-map", [BAKE, "{in}/spot.obj", "--out", "{out}/a.png", "--maps", "thickness",
                                     "--thickness-out", "{out}/A.png"], 2,
     "the AO map (--out) and the thickness map (--thickness-out) would both be written to '{out}/A.png'"),
    ("high-poly-empty-name", [BAKE, "{in}/spot.obj", "--out", "{out}/a.png", "--high-poly", ""], 2,
     "--high-poly '' is neither a mesh file nor a mesh in the input (meshes: spot)"),
    ("quality-unknown", [BAKE, "{in}/spot.obj", "--out", "{out}/a.png", "--quality", "9-bit"], 2,
     "argument --quality: invalid choice: '9-bit'"),
    ("occluders-unknown", [BAKE, "{in}/spot.obj", "--out", "{out}/a.png", "--occluders", "none"], 2,
     "argument --occluders: invalid choice: 'none'"),
    ("png-bits-unknown", [BAKE, "{in}/spot.obj", "--out", "{out}/a.png", "--png-bits", "12"], 2,
     "argument --png-bits: invalid choice: '12'"),
    *[(f"task-manifest-{name}", [BAKE, "--manifest", f"{{in}}/m_{name}.json", "--chunk", "0", "--out-dir", "{out}"], 2,
       message) for name, message in {
        "list": "is not a job manifest of this hao: expected an object, found list",
        "null": "is not a job manifest of this hao: expected an object, found NoneType",
        "empty-file": "cannot read the manifest '{in}/m_empty-file.json': Expecting value",
        "not-json": "cannot read the manifest '{in}/m_not-json.json': Expecting property name",
        "version-1": "version 1, this hao reads 2", "no-root": "'root' is missing",
        "no-outputs": "'outputs' is missing",
        "chunk-zero": "'chunk_size' must be between 1 and 1000000, found 0",
        "chunk-huge": "'chunk_size' must be a whole number, found Infinity",
        "chunk-bool": "'chunk_size' must be a whole number, found true",
        "chunk-text": "'chunk_size' must be a whole number, found \"10\"",
        "entries-text": "'entries' must be a list, found \"spot.obj\"",
        "entries-null": "'entries' must hold non-empty text, found null", "entries-empty": "'entries' is empty",
        "entry-absolute": "'entries' entry \"/etc/passwd\" must be a path relative to its folder",
        "entry-up": "'entries' entry \"../spot.obj\" must be a path relative",
        "entries-twice": "an input is named twice in 'entries'",
        "out-nul": "'out' contains a control character (NUL)", "out-path": "'out' must be a file name",
        "root-relative": "'root' must be an absolute folder", "unknown-field": "unknown field 'extra'",
        "frames-bad": "has a bad frame range: --frames '1-x'", "outputs-text": "'outputs' must be a list",
        "entry-newline": "'entries' entry \"a\\nb.obj\" contains a control character (a newline)",
    }.items()],
    ("verify-manifest-faulty", [FARM, "verify", "--manifest", "{in}/m_chunk-zero.json", "--out-dir", "{out}"], 2,
     "the manifest '{in}/m_chunk-zero.json' is not a job manifest of this hao"),
]


SMALL = ["--size", "16", "--directions", "4", "--margin", "1"]
JOB_FILES = {"openjd": ["job/asset_references.json", "job/job_parameters.json", "job/manifest.json",
                        "job/parameter_values.json", "job/template.json"],
             "flamenco": ["job/hao_bake.js", "job/job.json", "job/manifest.json"],
             "opencue": ["job/hao_commands.txt", "job/manifest.json"]}
# Input that is odd but valid (issue 38): exit 0 with exactly these files in the output folder,
# the inputs untouched. (id, arguments, the files written, relative to {out})
ACCEPTED = [
    ("hostile-folder-bake", [BAKE, "{in}/" + HOSTILE_FOLDER + "/h.obj", "--out", "{out}/h.png", *SMALL], ["h.png"]),
    *[(f"hostile-folder-farm-{kind}", [FARM, kind, "{in}/" + HOSTILE_FOLDER + "/h.obj", "--out-dir",
                                       "{out}/-o $(touch PWNED) {{x}}", "--bundle", "{out}/job", *SMALL], files)
      for kind, files in JOB_FILES.items()],
    ("hostile-output-name", [BAKE, "{in}/spot.obj", "--out", "{out}/-a $(touch PWNED) 'q' ünï 漢.png", *SMALL],
     ["-a $(touch PWNED) 'q' ünï 漢.png"]),
    ("maps-empty", [BAKE, "{in}/spot.obj", "--out", "{out}/a.png", "--maps", "", *SMALL], ["a.png"]),
    ("maps-named-twice", [BAKE, "{in}/spot.obj", "--out", "{out}/a.png", "--maps", "ao,thickness,thickness", *SMALL],
     ["a.png", "a_thickness.png"]),
    ("thickness-within-nothing", [BAKE, "{in}/spot.obj", "--out", "{out}/a.png", "--thickness-out", "{out}/t.exr",
                                  "--thickness-distance", "1e-30", *SMALL], ["a.png", "t.exr"]),
    ("spread-angle-sparse", [BAKE, "{in}/spot.obj", "--out", "{out}/a.png", "--spread-angle", "20", *SMALL,
                             "--directions", "64"], ["a.png"]),  # about 7.5 directions in the cone: a warning
    ("farm-extra-outputs-in-the-out-dir", [FARM, "openjd", "{in}/spot.obj", "--out-dir", "{out}/maps", "--bundle",
                                           "{out}/job", "--thickness-out", "{input}_t.png", "--gltf-out",
                                           "{input}.glb"], JOB_FILES["openjd"]),
    ("png-bits-for-one-png-of-two", [BAKE, "{in}/spot.obj", "--out", "{out}/a.exr", "--png-bits", "8",
                                     "--thickness-out", "{out}/t.png", *SMALL], ["a.exr", "t.png"]),
    ("alpha-texture-read", [BAKE, "{in}/alpha_texture.blend", "--object", "Floor", "--out", "{out}/a.png", *SMALL],
     ["a.png"]),
    ("alpha-missing-with-alpha-off", [BAKE, "{in}/alpha_missing.blend", "--object", "Floor", "--out",
                                      "{out}/a.png", "--alpha", "off", *SMALL], ["a.png"]),
]


def run_cli(args: list[str], tmp: Path, **kw) -> subprocess.CompletedProcess:
    """The shared runner (conftest.run_hao) with temporary files in `tmp`, run in `cwd` (default `tmp`)."""
    extra = {**cli_env(tmp), **kw.pop("env", {})}
    return run_hao(args, cwd=kw.pop("cwd", tmp), env=extra, timeout=300, **kw)


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
    prepared |= {case[0]: _case_args((*case[:2], 0, ""), inputs, tmp_path_factory.mktemp(case[0]))
                 for case in ACCEPTED}

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


@pytest.mark.parametrize("case", ACCEPTED, ids=[c[0] for c in ACCEPTED])
def test_cli_odd_but_valid_input(inputs, cli_runs, case):
    name, _template, files = case
    results, before = cli_runs
    proc, _message, out, tmp = results[name]
    assert proc.returncode == 0, proc.stderr
    assert all(line.startswith("hao: warning: ") for line in proc.stderr.splitlines()), proc.stderr
    written = sorted(str(p.relative_to(out)) for p in out.rglob("*") if p.is_file())
    assert written == sorted(files), written
    assert list(tmp.iterdir()) == [] and not list(out.rglob("PWNED")) and not list(tmp.parent.rglob("PWNED"))
    assert digest(inputs) == before


def test_enough_classes():
    """Issue 28, then 38: at least 200 classes across both entry points (the command line's here, the
    operators' below), a class being a refusal the user is told apart: cases that expect the
    same message count once (renaming a copy of a case adds nothing), argparse's own
    messages ('invalid choice', 'unrecognized arguments', ...) once each."""
    told = {("cli", c[3]) for c in CASES}
    told |= {("operator", c[-1]) for c in BAKE_OPERATOR_CASES + RENDER_OPERATOR_CASES}
    told |= {("accepted", c[0]) for c in ACCEPTED}
    assert len({c[0] for c in CASES + ACCEPTED}) == len(CASES) + len(ACCEPTED)
    assert len(told) >= 200, len(told)  # issue 38


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
