# SPDX-License-Identifier: GPL-3.0-or-later
"""The built extension zip installs and bakes; the command line works and fails cleanly."""
from __future__ import annotations

import os
import subprocess
import sys
import zipfile
from pathlib import Path

import numpy as np
import pytest

import bpy
from conftest import ROOT

SAMPLE = ROOT / "samples" / "spot.obj"


def run(args, **kw):
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    env.update(kw.pop("env", {}))
    return subprocess.run([sys.executable, *args], capture_output=True, text=True, cwd=kw.pop("cwd", ROOT),
                          env=env, timeout=600, **kw)


@pytest.fixture(scope="module")
def built_zip(tmp_path_factory):
    """The zip as a Windows or macOS user builds it: Python alone (-I -S: no site-packages,
    so no bpy, no PYTHONPATH), the README's command."""
    out = tmp_path_factory.mktemp("dist")
    proc = run(["-I", "-S", str(ROOT / "tools" / "build_extension.py"), str(out)])
    assert proc.returncode == 0, proc.stdout + proc.stderr
    (zip_path,) = out.glob("hao_ao-*.zip")
    return zip_path


def test_the_builder_is_blender_s_own_and_validates_the_zip(built_zip):
    """tools/blender_ext.py is the builder of the newest tested wheel, unchanged; Blender's
    validation (the same tool as its bpy wheel ships) accepts the zip."""
    shipped = Path(bpy.utils.system_resource('SCRIPTS')) / "addons_core" / "bl_pkg" / "cli" / "blender_ext.py"
    if bpy.app.version[:2] == (5, 3):
        assert (ROOT / "tools" / "blender_ext.py").read_bytes() == shipped.read_bytes()
    proc = run(["-I", str(shipped), "validate", str(built_zip)])
    assert proc.returncode == 0 and "Success" in proc.stdout + proc.stderr, proc.stdout + proc.stderr


def test_zip_contains_the_extension_and_no_dev_files(built_zip):
    names = set(zipfile.ZipFile(built_zip).namelist())
    for required in ("blender_manifest.toml", "__init__.py", "operators/bake_operator.py",
                     "hao_addon/gpu/bake_scatter.py", "gpu_shaders/bake_splat.frag",
                     "wheels/xatlas-0.0.11-cp311-cp311-win_amd64.whl"):
        assert required in names, required
    assert not any(n.startswith(("tests/", "bench/", "docs/", ".venv/", ".ci/")) for n in names)


def test_the_extension_carries_its_manual_and_no_made_up_website(built_zip):
    """There is no public site: the manifest names none, and the zip holds the built manual
    that the add-on's preferences open (operators/preferences.py)."""
    import tomllib
    names = set(zipfile.ZipFile(built_zip).namelist())
    assert {"site/index.html", "site/baking-in-blender.html", "site/benchmarks.html"} <= names
    manifest = tomllib.loads(zipfile.ZipFile(built_zip).read("blender_manifest.toml").decode())
    assert "website" not in manifest


def test_installed_zip_bakes(built_zip, tmp_path):
    out = tmp_path / "ao.png"
    proc = run([str(ROOT / "tests" / "scripts" / "install_and_bake.py"), str(built_zip), str(out)],
               env={"BLENDER_USER_RESOURCES": str(tmp_path / "user")}, cwd=tmp_path)
    assert "INSTALLED_BAKE_OK" in proc.stdout, proc.stdout[-3000:] + proc.stderr[-3000:]
    assert out.stat().st_size > 1000


def read_png16(path):
    import struct
    import zlib
    d = Path(path).read_bytes()
    i, idat = 8, b""
    while i < len(d):
        n = struct.unpack(">I", d[i:i + 4])[0]
        tag = d[i + 4:i + 8]
        if tag == b"IHDR":
            w, h, depth = struct.unpack(">IIB", d[i + 8:i + 17])
        if tag == b"IDAT":
            idat += d[i + 8:i + 8 + n]
        i += 12 + n
    assert depth == 16
    raw = np.frombuffer(zlib.decompress(idat), np.uint8).reshape(h, 1 + 2 * w)[:, 1:]
    return raw.copy().view(">u2").reshape(h, w) / 65535.0


def test_cli_bakes_obj_to_png16_and_exr(tmp_path):
    png = tmp_path / "spot.png"
    proc = run(["-m", "hao_addon", "bake", str(SAMPLE), "--size", "128", "--directions", "32", "--out", str(png)])
    assert proc.returncode == 0, proc.stderr
    img = read_png16(png)
    assert img.shape == (128, 128) and 0.0 <= img.min() < 0.7 and img.max() == 1.0
    exr = tmp_path / "spot.exr"
    proc = run(["-m", "hao_addon", "bake", str(SAMPLE), "--size", "128", "--directions", "32", "--out", str(exr),
                "--max-distance", "0.2", "--falloff", "wendland", "--margin", "2"])
    assert proc.returncode == 0, proc.stderr
    loaded = bpy.data.images.load(str(exr))
    px = np.empty(128 * 128 * 4, np.float32)
    loaded.pixels.foreach_get(px)
    bpy.data.images.remove(loaded)
    assert np.isfinite(px).all() and px.reshape(-1, 4)[:, 0].min() >= 0.0


def test_cli_bakes_blend_and_glb_inputs_with_auto_unwrap(tmp_path):
    # A .blend and a .glb of a UV-less cube on a floor, written by Blender itself.
    script = f"""
import bpy
bpy.ops.wm.read_factory_settings(use_empty=True)
bpy.ops.mesh.primitive_cube_add(location=(0, 0, 1))
cube = bpy.context.active_object
cube.name = "Box"
cube.data.uv_layers.remove(cube.data.uv_layers[0])
bpy.ops.mesh.primitive_plane_add(size=10)
bpy.ops.wm.save_as_mainfile(filepath=r"{tmp_path / 'scene.blend'}")
bpy.ops.export_scene.gltf(filepath=r"{tmp_path / 'scene.glb'}")
import os, sys
sys.stdout.flush()
os._exit(0)  # bpy 4.2 segfaults at interpreter exit after a glTF export (exit -11)
"""
    proc = run(["-c", script])
    assert proc.returncode == 0, proc.stderr
    for name in ("scene.blend", "scene.glb"):
        out = tmp_path / f"{name}.png"
        proc = run(["-m", "hao_addon", "bake", str(tmp_path / name), "--object", "Box", "--size", "64",
                    "--directions", "32", "--uv-map", "auto", "--out", str(out)])
        assert proc.returncode == 0, proc.stderr
        assert "AO_UV" in proc.stdout  # the cube had no UVs: unwrapped by xatlas
        img = read_png16(out)
        assert img.min() < 0.9  # the floor occludes the box's bottom


@pytest.mark.parametrize("args, message", [
    (["missing.obj", "--out", "x.png"], "input file not found"),
    (["samples/spot.obj", "--out", "x.jpg"], "unsupported output extension"),
    (["samples/spot.obj", "--out", "samples/spot.obj/dir/x.png"], "is a file, not a folder"),
    (["samples/spot.obj", "--out", "x.png", "--size", "0"], "map size"),
    (["samples/spot.obj", "--out", "x.png", "--uv-map", "Nope"], "no UV map named 'Nope'"),
    (["samples/spot.obj", "--out", "x.png", "--object", "Nope"], "no mesh object named 'Nope'"),
    (["samples/spot.obj", "--out", "x.png", "--falloff", "cubic"], "invalid choice"),
    (["samples/spot.obj", "--out", "x.png", "--samples-per-texel", "5"], "invalid choice"),
])
def test_cli_bad_input_exits_2_with_one_line(tmp_path, args, message):
    proc = run(["-m", "hao_addon", "bake", *args])
    assert proc.returncode == 2, (proc.returncode, proc.stderr)
    lines = [l for l in proc.stderr.splitlines() if l.startswith("hao:")]
    assert len(lines) == 1 and message in lines[0], proc.stderr
    assert "Traceback" not in proc.stderr
    assert not (ROOT / "x.png").exists()


def test_cli_is_registered_as_a_blender_command(addon):
    from hao_ext.operators import cli_command
    assert cli_command._handle is not None
    assert cli_command._cli(["bake", "missing.obj", "--out", "x.png"]) == 2


def test_manifest_bundles_xatlas_for_every_supported_python_and_platform():
    import tomllib  # Python 3.11+
    manifest = tomllib.loads((ROOT / "blender_manifest.toml").read_text())
    wheels = [Path(w).name for w in manifest["wheels"]]
    assert all((ROOT / "wheels" / w).is_file() for w in wheels)
    tags = {"linux-x64": "manylinux", "macos-arm64": "macosx_11_0_arm64", "macos-x64": "macosx_10_14_x86_64",
            "windows-x64": "win_amd64"}
    for python in ("cp311", "cp313"):  # Blender 4.2-5.0 and 5.1-5.2
        for platform in manifest["platforms"]:
            assert any(w.startswith(f"xatlas-0.0.11-{python}-{python}-") and tags[platform] in w for w in wheels), \
                (python, platform)
