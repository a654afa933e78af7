# SPDX-License-Identifier: GPL-3.0-or-later
"""Table-driven bad input: every class gets one clear line and loses nothing.

Command line (``bake``, ``render-ao``): the exit code, stderr exactly one ``hao: error:`` line
naming the problem, nothing on stdout, no file in the output folder or the temporary folder
(Blender's own ``blender_*`` included), and every input file unchanged. Operators: the
report, and the scene unchanged (no image, UV map, attribute or material added).
"""
from __future__ import annotations

import hashlib
import os
import shutil
import subprocess
import sys
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
    return folder


def digest(folder: Path) -> dict[str, str]:
    return {p.name: hashlib.sha256(p.read_bytes()).hexdigest() for p in sorted(folder.iterdir()) if p.is_file()}


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
    ("output-folder-missing", [BAKE, "{in}/spot.obj", "--out", "{out}/no/such/a.png"], 2, "folder does not exist"),
    ("output-folder-is-file", [BAKE, "{in}/spot.obj", "--out", "{in}/spot.obj/a.png"], 2, "folder does not exist"),
    ("output-unwritable", [BAKE, "{in}/spot.obj", "--out", "{locked}/a.png"], 2, "permission denied"),
    ("output-name-too-long", [BAKE, "{in}/spot.obj", "--out", "{out}/" + "n" * 260 + ".png"], 2,
     "longer than the file system"),
    ("output-is-folder", [BAKE, "{in}/spot.obj", "--out", "{in}/blend1"], 2, "unsupported output extension"),
    ("output-is-folder-png", [BAKE, "{in}/spot.obj", "--out", "{in}/dir.png"], 2, "it is a folder"),
    ("report-folder-missing", [BAKE, "{in}/spot.obj", "--out", "{out}/a.png", "--json", "{out}/no/r.json"], 2,
     "cannot write the report"),
    ("texture-set-one-object", [BAKE, "{in}/spot.obj", "--out", "{out}/a.png", "--texture-set"], 2,
     "--texture-set bakes several meshes"),
    ("object-twice", [BAKE, "{in}/spot.obj", "--out", "{out}/a.png", "--object", "spot", "--object", "spot"], 2,
     "names the same mesh twice"),
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
    ("render-output-folder-missing", [RENDER, "{in}/scene.blend", "--out", "{out}/no/a.png"], 2,
     "folder does not exist"),
    ("render-output-extension", [RENDER, "{in}/scene.blend", "--out", "{out}/a.tif"], 2,
     "unsupported output extension"),
]


def run_cli(args: list[str], tmp: Path, **kw) -> subprocess.CompletedProcess:
    env = {**os.environ, "PYTHONPATH": str(ROOT), "TMPDIR": str(tmp), "TEMP": str(tmp), "TMP": str(tmp)}
    env.update(kw.pop("env", {}))
    return subprocess.run([sys.executable, "-m", "hao_addon", *args], capture_output=True, text=True, env=env,
                          cwd=kw.pop("cwd", tmp), timeout=300, **kw)


@pytest.mark.parametrize("case", CASES, ids=[c[0] for c in CASES])
def test_cli_bad_input(inputs, tmp_path, case):
    _name, template, code, message = case
    out, tmp = tmp_path / "out", tmp_path / "tmp"
    out.mkdir()
    tmp.mkdir()
    subs = {"{in}": str(inputs), "{out}": str(out), "{locked}": str(unwritable_folder(tmp_path))}
    args = []
    for arg in template:
        for token, value in subs.items():
            arg = arg.replace(token, value)
        args.append(arg)
    before = digest(inputs)
    proc = run_cli(args, tmp)
    assert proc.returncode == code, (proc.returncode, proc.stderr)
    lines = proc.stderr.splitlines()
    assert len(lines) == 1 and lines[0].startswith("hao: error: ") and message in lines[0], proc.stderr
    assert proc.stdout == ""
    assert list(out.iterdir()) == [] and list(tmp.iterdir()) == [], (list(out.iterdir()), list(tmp.iterdir()))
    assert digest(inputs) == before


def test_enough_classes():
    assert len(CASES) >= 40


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


@pytest.mark.parametrize("setup, message", [
    ("colliding-names", "would both be saved as"),
    ("relative-path-unsaved", "relative to the .blend file"),
    ("unsupported-extension", "unsupported output extension"),
    ("missing-uv-map", "no UV map named 'Nope'"),
    ("nan-vertex", "NaN"),
    ("name-too-long", "longer than the file system"),
    ("nothing-selected", "Select one or more mesh objects"),
])
def test_bake_operator_bad_input(scene, tmp_path, setup, message):
    a, b = two_cubes("a b", "a_b")
    if setup == "colliding-names":
        small_settings(scene, filepath=str(tmp_path / "pair.png"))
    elif setup == "relative-path-unsaved":
        assert bpy.data.filepath == ""
        small_settings(scene, filepath="//ao.png")
    elif setup == "unsupported-extension":
        small_settings(scene, filepath=str(tmp_path / "ao.bmp"))
    elif setup == "missing-uv-map":
        small_settings(scene, uv_mode='NAMED', uv_map="Nope")
    elif setup == "nan-vertex":
        b.data.vertices[0].co = (float("nan"), 0.0, 0.0)
        small_settings(scene)
    elif setup == "name-too-long":
        small_settings(scene, filepath=str(tmp_path / ("x" * 300 + ".png")))
    elif setup == "nothing-selected":
        select_only()
    before = scene_state()
    with pytest.raises(RuntimeError, match=message):
        bpy.ops.object.hao_bake_ao()
    assert scene_state() == before
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("setup, message", [
    ("resolution-beyond-limits", "texture limit"),
    ("relative-path-unsaved", "relative to the .blend file"),
    ("missing-folder", "folder does not exist"),
    ("no-mesh", "no visible mesh objects"),
])
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
    elif setup == "missing-folder":
        path = str(tmp_path / "no" / "hao.png")
    before = scene_state()
    try:
        with pytest.raises(RuntimeError, match=message):
            bpy.ops.render.hao_render_ao(filepath=path)
    finally:
        r.resolution_x, r.resolution_y, r.resolution_percentage = saved
    assert scene_state() == before
    assert list(tmp_path.iterdir()) == []
